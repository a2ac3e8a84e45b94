// volmorph diff A B: compare two images the way OpenImageIO's idiff does (same thresholds, same
// verdicts, same exit codes), through ImageBufAlgo::compare.
//
// Verdict (idiff 2.4): a pixel fails when some channel differs by more than --fail (and, when
// given, by more than --failrelative of the mean of the two values), and warns likewise with
// --warn. PASS when at most --allowfailures pixels fail; otherwise FAIL when more than failpercent%
// of the pixels fail or any difference exceeds --hardfail; otherwise WARN when more than
// warnpercent% warn or any difference exceeds --hardwarn; otherwise PASS. (So, as in idiff 2.4,
// warnings alone, with no failing pixel, pass.) Images of different sizes are compared over the
// union of their windows (missing pixels count as 0), as idiff does, so a size mismatch is a
// failure.
#include "Common.h"

#include <volmorph/core/AtomicFile.h>

#include <volmorph/render/Output.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cstdio>
#include <limits>
#include <memory>
#include <string>

namespace volmorph::cli {
namespace {

/// idiff's exit codes.
enum DiffStatus { kDiffPass = 0, kDiffWarn = 1, kDiffFail = 2, kDiffSize = 3, kDiffFile = 4 };

struct DiffArgs {
    std::string a, b, output;
    float fail = 1e-6f, failPercent = 0.0f, hardFail = std::numeric_limits<float>::infinity();
    float failRelative = 0.0f, warnRelative = 0.0f;
    unsigned allowFailures = 0;
    float warn = 1e-6f, warnPercent = 0.0f, hardWarn = std::numeric_limits<float>::infinity();
    float scale = 1.0f;
    bool absolute = false, outputOnlyIfDifferent = false, quiet = false, verbose = false;
};

bool readFloat(const std::string& path, OIIO::ImageBuf& image)
{
    image.reset(path);
    if (image.read(0, 0, /*force*/ true, OIIO::TypeDesc::FLOAT)) return true;
    std::string why = image.geterror();
    while (!why.empty() && why.back() == '\n') why.pop_back();
    std::fprintf(stderr, "%s: cannot read image (%s)\n", path.c_str(),
                 why.empty() ? "unknown error" : why.c_str());
    return false;
}

std::string describeSize(const OIIO::ImageSpec& s)
{
    return std::to_string(s.width) + "x" + std::to_string(s.height) + ", " +
           std::to_string(s.nchannels) + " channels";
}

bool writeDifference(const DiffArgs& args, const OIIO::ImageBuf& a, const OIIO::ImageBuf& b)
{
    OIIO::ImageBuf diff =
        args.absolute ? OIIO::ImageBufAlgo::absdiff(a, b) : OIIO::ImageBufAlgo::sub(a, b);
    if (args.scale != 1.0f) diff = OIIO::ImageBufAlgo::mul(diff, args.scale);
    try {
        writeAtomically(args.output, [&diff](const std::filesystem::path& temporary) {
            if (!diff.write(temporary.string(), OIIO::TypeDesc::FLOAT))
                throw std::runtime_error(diff.geterror());
        });
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: cannot write the difference image (%s)\n", args.output.c_str(),
                     e.what());
        return false;
    }
    return true;
}

int runDiff(const DiffArgs& args)
{
    if (!args.quiet) std::printf("Comparing \"%s\" and \"%s\"\n", args.a.c_str(), args.b.c_str());
    OIIO::ImageBuf a, b;
    if (!readFloat(args.a, a) || !readFloat(args.b, b)) return kDiffFile;

    const OIIO::ImageSpec& sa = a.spec();
    const OIIO::ImageSpec& sb = b.spec();
    const bool sameSize = sa.width == sb.width && sa.height == sb.height && sa.depth == sb.depth &&
                          sa.nchannels == sb.nchannels && sa.x == sb.x && sa.y == sb.y;
    double pixels = double(sa.width) * double(sa.height) * double(sa.depth);
    if (pixels == 0.0) pixels = 1.0;

    // Over the union of both windows, missing pixels counting as 0, as idiff. (OpenImageIO 2.4
    // leaves CompareResults::error unset on success, so it is not read.)
    const OIIO::ImageBufAlgo::CompareResults r = OIIO::ImageBufAlgo::compare(
        a, b, args.fail, args.warn, args.failRelative, args.warnRelative);
    int status = kDiffPass;
    if (r.nfail <= args.allowFailures)
        status = kDiffPass;
    else if (double(r.nfail) > args.failPercent / 100.0 * pixels ||
             r.maxerror > double(args.hardFail))
        status = kDiffFail;
    else if (double(r.nwarn) > args.warnPercent / 100.0 * pixels ||
             r.maxerror > double(args.hardWarn))
        status = kDiffWarn;

    if (!args.quiet && (args.verbose || status != kDiffPass)) {
        if (!sameSize)
            std::printf("  Images differ in size: %s vs %s\n", describeSize(sa).c_str(),
                        describeSize(sb).c_str());
        std::printf("  Mean error = %g\n  RMS error = %g\n  Peak SNR = %g\n  Max error  = %g",
                    r.meanerror, r.rms_error, r.PSNR, r.maxerror);
        if (r.maxerror != 0.0) {
            const int c = r.maxc;
            const std::string channel = c < int(sa.channelnames.size()) ? sa.channelnames[size_t(c)]
                                        : c < int(sb.channelnames.size())
                                            ? sb.channelnames[size_t(c)]
                                            : "channel " + std::to_string(c);
            std::printf(" @ (%d, %d, %s)", r.maxx, r.maxy, channel.c_str());
        }
        std::printf("\n  %llu pixels (%.3g%%) over %g\n  %llu pixels (%.3g%%) over %g\n",
                    static_cast<unsigned long long>(r.nwarn), 100.0 * double(r.nwarn) / pixels,
                    double(args.warn), static_cast<unsigned long long>(r.nfail),
                    100.0 * double(r.nfail) / pixels, double(args.fail));
    }
    if (!args.output.empty() && (r.maxerror != 0.0 || !args.outputOnlyIfDifferent))
        if (!writeDifference(args, a, b)) return kDiffFile;

    static const char* const kVerdict[] = {"PASS", "WARNING", "FAILURE"};
    if (status == kDiffFail && args.quiet)
        std::fprintf(stderr, "FAILURE\n");
    else if (!args.quiet)
        std::printf("%s\n", kVerdict[status]);
    std::fflush(stdout);
    return status;
}

} // namespace

Command addDiffCommand(CLI::App& app)
{
    auto a = std::make_shared<DiffArgs>();
    CLI::App* sub = app.add_subcommand(
        "diff",
        "Compare two images like OpenImageIO's idiff (exit 0 pass, 1 warn, 2 fail, 4 file error)");
    sub->add_option("A", a->a, "first image (e.g. the reference)")->required();
    sub->add_option("B", a->b, "second image")->required();
    sub->add_option("--fail", a->fail,
                    "failure threshold: absolute difference in any channel (default 1e-6)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--failpercent", a->failPercent,
                    "allow this percentage of pixels over --fail (default 0)")
        ->check(CLI::Range(0.0, 100.0));
    sub->add_option("--hardfail", a->hardFail,
                    "fail if any one difference exceeds this (default inf)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--failrelative", a->failRelative,
                    "also require this relative difference to fail (default 0)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--allowfailures", a->allowFailures,
                    "pass when at most this many pixels fail (default 0)");
    sub->add_option("--warnrelative", a->warnRelative,
                    "also require this relative difference to warn (default 0)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--warn", a->warn, "warning threshold (default 1e-6)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--warnpercent", a->warnPercent,
                    "allow this percentage of pixels over --warn (default 0)")
        ->check(CLI::Range(0.0, 100.0));
    sub->add_option("--hardwarn", a->hardWarn,
                    "warn if any one difference exceeds this (default inf)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("-o,--output", a->output, "write the difference image A - B (float)");
    sub->add_flag("--od", a->outputOnlyIfDifferent,
                  "write the difference image only when the images differ");
    sub->add_flag("--abs", a->absolute, "difference image of |A - B|");
    sub->add_option("--scale", a->scale, "scale the difference image by this factor");
    sub->add_flag("-q,--quiet", a->quiet, "print only a failure");
    sub->add_flag("-v,--verbose", a->verbose, "print the statistics even when the images pass");
    return {sub, [a] { return runDiff(*a); }};
}

} // namespace volmorph::cli
