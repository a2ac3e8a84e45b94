// Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen Scrambling"): the
// renderer's low-discrepancy numbers. Dimensions come in groups of four, each group the first four
// Sobol dimensions (Joe and Kuo's direction numbers) with its own nested uniform scramble and its
// own shuffle of the sample index ("padding", as pbrt-v4's PaddedSobolSampler), so any run of up
// to four dimensions of a group is stratified, and the first 2^m samples of a pixel are a
// (0, m, 2)-net in each pair of a group. Everything is a function of (index, seed): no state, no
// table shared between threads.
#pragma once

#include <array>
#include <cstdint>

namespace volmorph::render::sobol {

/// The generator matrices of Sobol dimensions 0 to 3 as 32 column vectors each (bit 31 the
/// coarsest), from the primitive polynomials and initial numbers of Joe and Kuo (2008): dimension
/// 0 is van der Corput's; 1: s = 1, a = 0, m = 1; 2: s = 2, a = 1, m = 1 3; 3: s = 3, a = 1,
/// m = 1 3 1.
constexpr std::array<std::array<uint32_t, 32>, 4> makeMatrices()
{
    std::array<std::array<uint32_t, 32>, 4> v{};
    for (int k = 0; k < 32; ++k) v[0][k] = 1u << (31 - k);
    struct Poly {
        int s;
        uint32_t a;
        uint32_t m[3];
    };
    constexpr Poly polys[3] = {{1, 0, {1, 0, 0}}, {2, 1, {1, 3, 0}}, {3, 1, {1, 3, 1}}};
    for (int d = 1; d < 4; ++d) {
        const Poly& p = polys[d - 1];
        for (int k = 0; k < 32; ++k) {
            if (k < p.s) {
                v[d][k] = p.m[k] << (31 - k);
                continue;
            }
            uint32_t x = v[d][k - p.s] ^ (v[d][k - p.s] >> p.s);
            for (int j = 1; j < p.s; ++j)
                if ((p.a >> (p.s - 1 - j)) & 1u) x ^= v[d][k - j];
            v[d][k] = x;
        }
    }
    return v;
}

inline constexpr std::array<std::array<uint32_t, 32>, 4> kMatrices = makeMatrices();

/// The matrices by byte: kBytes[dim][b][v] is the XOR of the columns 8 b to 8 b + 7 that byte
/// value v selects, so a point is four lookups instead of a loop over 32 bits.
constexpr std::array<std::array<std::array<uint32_t, 256>, 4>, 4> makeByteTables()
{
    std::array<std::array<std::array<uint32_t, 256>, 4>, 4> t{};
    for (int d = 0; d < 4; ++d)
        for (int b = 0; b < 4; ++b)
            for (uint32_t v = 0; v < 256; ++v) {
                uint32_t x = 0;
                for (int k = 0; k < 8; ++k)
                    if (v & (1u << k)) x ^= kMatrices[d][8 * b + k];
                t[d][b][v] = x;
            }
    return t;
}

inline constexpr std::array<std::array<std::array<uint32_t, 256>, 4>, 4> kBytes = makeByteTables();

/// Sobol dimension `dim` (0 to 3) of point `index`, as 32 bits of a fraction.
inline uint32_t point(uint32_t index, int dim)
{
    const auto& t = kBytes[dim];
    return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^
           t[3][index >> 24];
}

inline uint32_t reverseBits(uint32_t x)
{
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/// A nested uniform (Owen) scramble of a 32-bit fraction: each bit flipped by a hash of the bits
/// above it and the seed (Laine and Karras's permutation, on the reversed bits, with Burley's
/// constants). Keeps every elementary interval's count, so a net stays a net.
inline uint32_t owenScramble(uint32_t x, uint32_t seed)
{
    x = reverseBits(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverseBits(x);
}

/// A 32-bit hash of two words (for the scrambles' seeds).
inline uint32_t hash(uint64_t a, uint64_t b)
{
    uint64_t z = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return uint32_t((z ^ (z >> 31)) >> 32);
}

/// The index of sample `index` in group `group`'s shuffle of the sequence `seed` (a pixel's): an
/// Owen scramble of the index, which maps the first 2^m indices onto an aligned block of 2^m, so a
/// pixel's first 2^m samples are a net whatever the seed.
inline uint32_t shuffledIndex(uint32_t index, uint32_t group, uint64_t seed)
{
    return owenScramble(index, hash(seed, 2u * group));
}

/// Dimension `dim` (any; its group is dim / 4) of the point at `shuffled` (shuffledIndex of that
/// group), scrambled with a seed of its own, in [0, 1).
inline double scrambledPoint(uint32_t shuffled, uint32_t dim, uint64_t seed)
{
    const uint32_t bits = owenScramble(point(shuffled, int(dim % 4)), hash(seed, 2u * dim + 1u));
    return double(bits) * (1.0 / 4294967296.0);
}

/// Dimension `dim` of sample `index` of the sequence `seed`: group dim / 4 shuffles the index and
/// scrambles its four dimensions with seeds of its own.
inline double sample(uint32_t index, uint32_t dim, uint64_t seed)
{
    return scrambledPoint(shuffledIndex(index, dim / 4, seed), dim, seed);
}

} // namespace volmorph::render::sobol
