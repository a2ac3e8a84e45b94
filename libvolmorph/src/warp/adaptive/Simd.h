// The approximated warp's vector arithmetic (GCC's vector extension), and the builds its kernels
// are compiled in (AVX2, AVX2 with AVX-512VL, baseline), picked by the CPU at run time.
#pragma once

#include "warp/AdaptiveWarp.h"

#include <algorithm>
#include <cmath>

/// The per-voxel helpers are inlined into every build of the kernels that use them.
#if defined(__GNUC__)
#define VOLMORPH_ALWAYS_INLINE __attribute__((always_inline))
#else
#define VOLMORPH_ALWAYS_INLINE
#endif

// The leaf kernel, the bound and the lattice's sums are compiled three times on x86-64 with GCC:
// for AVX2 (8 voxels of a row in one instruction), for AVX2 with AVX-512VL (the same 8-lane code
// with 32 vector registers instead of 16: fewer spills) and for the baseline, and picked by the
// CPU at run time. Each lane does the same IEEE operations in every build (no FMA contraction:
// -ffp-contract=off on their units), so the points are bit-identical whatever the machine; the
// warp tests check it with AdaptiveWarp's build limit.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define VOLMORPH_HAVE_AVX2_KERNEL 1
#define VOLMORPH_AVX2 __attribute__((target("avx2")))
#define VOLMORPH_AVX512 __attribute__((target("avx2,avx512f,avx512vl,avx512dq,avx512bw")))
/// A kernel's three builds, named f##Baseline, f##Avx2, f##Avx512, for pickBuild.
#define VOLMORPH_BUILDS(f) f##Baseline, f##Avx2, f##Avx512
#else
#define VOLMORPH_BUILDS(f) f##Baseline, f##Baseline, f##Baseline
#endif

namespace volmorph::detail {
// Internal linkage: each unit inlines these into its own builds, compiled with its own flags.
namespace {

// The warp's vector arithmetic uses GCC's vector extension: one AVX register, or two SSE ones in
// the baseline build, with the same IEEE operations per lane in both. 8 floats: the kernel's rows
// of 8 voxels along z and the bound's 8 pairs; 4 doubles: the exact sums' 4 pairs and a leaf's 4
// corners. Loads and stores are unaligned (std::vector's storage is only 16-byte aligned) and go
// through types that alias their element type only, not the vectors' own pointers.
typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));
typedef float v8fu __attribute__((vector_size(32), aligned(4)));
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4l __attribute__((vector_size(32)));
typedef double v4du __attribute__((vector_size(32), aligned(8)));

/// Lane-wise maximum and minimum (of v8f or v4d).
template <class V>
VOLMORPH_ALWAYS_INLINE inline V vmax(V a, V b)
{
    return a > b ? a : b;
}
template <class V>
VOLMORPH_ALWAYS_INLINE inline V vmin(V a, V b)
{
    return a < b ? a : b;
}

/// The voxels' offsets along a row (z).
constexpr v8f kZ = {0, 1, 2, 3, 4, 5, 6, 7};

VOLMORPH_ALWAYS_INLINE inline v8f load8(const float* p)
{
    return *reinterpret_cast<const v8fu*>(p);
}
VOLMORPH_ALWAYS_INLINE inline void store8(float* p, v8f v)
{
    *reinterpret_cast<v8fu*>(p) = v;
}
VOLMORPH_ALWAYS_INLINE inline v8f splat8(float v)
{
    return v8f{v, v, v, v, v, v, v, v};
}
VOLMORPH_ALWAYS_INLINE inline v8f vabs(v8f v)
{
    return reinterpret_cast<v8f>(reinterpret_cast<v8i>(v) & 0x7fffffff);
}
VOLMORPH_ALWAYS_INLINE inline v8f vsqrt(v8f v)
{
    v8f r;
    for (int l = 0; l < 8; ++l) r[l] = __builtin_sqrtf(v[l]); // one sqrtps per register (no errno)
    return r;
}

VOLMORPH_ALWAYS_INLINE inline v4d load4(const double* p)
{
    return *reinterpret_cast<const v4du*>(p);
}
VOLMORPH_ALWAYS_INLINE inline void store4(double* p, v4d v)
{
    *reinterpret_cast<v4du*>(p) = v;
}
VOLMORPH_ALWAYS_INLINE inline v4d splat(double v)
{
    return v4d{v, v, v, v};
}
VOLMORPH_ALWAYS_INLINE inline v4d vabs(v4d v)
{
    return reinterpret_cast<v4d>(reinterpret_cast<v4l>(v) & 0x7fffffffffffffffLL);
}
VOLMORPH_ALWAYS_INLINE inline v4d vsqrt(v4d v)
{
    v4d r;
    for (int l = 0; l < 4; ++l) r[l] = __builtin_sqrt(v[l]);
    return r;
}

/// Sums over pairs, 8 lanes of single precision accumulated in double (two 4-lane halves).
VOLMORPH_ALWAYS_INLINE inline v4d lowHalf(v8f v)
{
    return __builtin_convertvector(__builtin_shufflevector(v, v, 0, 1, 2, 3), v4d);
}
VOLMORPH_ALWAYS_INLINE inline v4d highHalf(v8f v)
{
    return __builtin_convertvector(__builtin_shufflevector(v, v, 4, 5, 6, 7), v4d);
}
struct WideSum {
    v4d lo{}, hi{};
    VOLMORPH_ALWAYS_INLINE void add(v8f v)
    {
        lo += lowHalf(v);
        hi += highHalf(v);
    }
    VOLMORPH_ALWAYS_INLINE double total() const
    {
        const v4d s = lo + hi;
        return (s[0] + s[1]) + (s[2] + s[3]);
    }
};

/// max(|q| - half, 0): how far a point lies beyond an element's half-extent along one of its axes.
template <class V>
VOLMORPH_ALWAYS_INLINE inline V outside(V q, V half)
{
    return vmax(vabs(q) - half, V{});
}

/// Of a kernel's builds (VOLMORPH_BUILDS), the one `build` names.
template <typename F>
F pickBuild(KernelBuild build, F baseline, F avx2, F avx512)
{
    switch (build) {
    case KernelBuild::Avx512:
        return avx512;
    case KernelBuild::Avx2:
        return avx2;
    case KernelBuild::Baseline:
        break;
    }
    return baseline;
}

} // namespace
} // namespace volmorph::detail
