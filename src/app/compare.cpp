// `keithray psnr` and `keithray compare`: a test image against a reference, 8-bit (PPM, PNG)
// or HDR (OpenEXR, PFM).
#include "app/compare.h"

#include <cstdio>
#include <filesystem>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/args.h"
#include "core/image_compare.h"
#include "core/file_write.h"
#include "core/image_formats.h"
#include "core/image_io.h"
#include "core/text.h"

namespace kr {

namespace {

constexpr const char* kCompareUsage = R"(Usage: keithray compare TEST REFERENCE [options]

Compares TEST with REFERENCE (OpenEXR, PFM, PPM or PNG) for CI: prints one verdict line
with the figures and exits 0 when the images agree, 1 when they do not or a file cannot
be read, 2 on bad usage. At least one criterion is needed:
  --min-psnr DB      PSNR of the 8-bit images at least DB (an HDR image is tone mapped
                     with the default sigmoid first)
  --max-rmse X       RMS error at most X (radiance of two HDR images; else 8-bit values
                     over 255)
  --max-relmse X     relative MSE, mean of (t - r)^2 / (r^2 + 0.01), at most X
  --statistical      both EXR renders with their variance layer (of a denoised render,
                     its raw.R/G/B are tested, not its biased R, G, B): fails when the images
                     differ by more than their noise explains (per 8x8 block and channel,
                     Welch z test, blocks of 8, 16, ... up to the whole image,
                     Bonferroni over all of them, plus a chi-square over the 8x8
                     ones), with false-alarm rate --alpha
  --alpha A          the statistical test's false-alarm rate (default 1e-4)
  --block N          its smallest block's side in pixels (default 8)
  --diff OUT.png     write a false-colour picture of the per-pixel error (|z| with
                     --statistical, else the RMS over the channels) with a colour bar
)";

constexpr const char* kPsnrUsage = R"(Usage: keithray psnr IMAGE REFERENCE

Prints the PSNR in dB of two 8-bit images (PPM or PNG, e.g. a render against the brief's
reference), or "rmse X relmse Y" of two HDR ones (OpenEXR or PFM). Exit status: 0, 1 when
a file cannot be read or the sizes differ, 2 on bad usage.
)";

// An image as compared: its radiance when it is HDR, and its 8-bit form (an HDR image tone
// mapped by the default sigmoid).
struct InputImage {
    std::string name;
    bool hdr = false;
    HdrImage radiance;
    Rgb8Image rgb8;
};

InputImage load_input(const std::string& path) {
    ImageFile file = read_image_file(path);
    InputImage in;
    in.name = path;
    in.hdr = file.hdr;
    in.radiance = std::move(file.radiance);
    in.rgb8 = in.hdr ? tonemap(in.radiance.radiance(), kDefaultToneMap) : std::move(file.rgb8);
    return in;
}

void check_sizes(const InputImage& a, const InputImage& b) {
    if (a.rgb8.width != b.rgb8.width || a.rgb8.height != b.rgb8.height)
        throw std::runtime_error(quoted_path(a.name) + " is " + std::to_string(a.rgb8.width) + "x" + std::to_string(a.rgb8.height) +
                                 " but " + quoted_path(b.name) + " is " + std::to_string(b.rgb8.width) + "x" +
                                 std::to_string(b.rgb8.height) + "; expected the same size");
}

// Errors on radiance when both are HDR, else on the 8-bit values.
ImageErrors pair_errors(const InputImage& test, const InputImage& reference) {
    return test.hdr && reference.hdr ? radiance_errors(test.radiance, reference.radiance)
                                     : rgb8_errors(test.rgb8, reference.rgb8);
}

struct CompareOptions {
    std::string test, reference;
    std::optional<double> min_psnr, max_rmse, max_relmse;
    bool statistical = false;
    StatisticalSettings stats;
    std::optional<std::string> diff;
};

CompareOptions parse_compare(int argc, char** argv) {
    CompareOptions o;
    std::vector<std::string> files;
    std::string test_flag;  // --alpha or --block, which only the statistical test reads
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        if (arg == "-h" || arg == "--help") throw UsageError{};
        else if (arg == "--min-psnr") o.min_psnr = parse_number(arg, args.value(), 0, 1000);
        else if (arg == "--max-rmse") o.max_rmse = parse_number(arg, args.value(), 0, 1e30);
        else if (arg == "--max-relmse") o.max_relmse = parse_number(arg, args.value(), 0, 1e30);
        else if (arg == "--statistical") o.statistical = true;
        else if (arg == "--alpha") o.stats.alpha = parse_number(arg, args.value(), 1e-300, 0.5), test_flag = arg;
        else if (arg == "--block") o.stats.block = int(parse_integer(arg, args.value(), 1, 4096)), test_flag = arg;
        else if (arg == "--diff") o.diff = args.value();
        else if (!arg.empty() && arg[0] == '-') throw UsageError{"unknown option " + quote_user_text(arg)};
        else files.push_back(arg);
    }
    if (files.size() != 2) throw UsageError{"compare needs two image files, TEST and REFERENCE"};
    if (!o.min_psnr && !o.max_rmse && !o.max_relmse && !o.statistical)
        throw UsageError{"compare needs a criterion: --min-psnr, --max-rmse, --max-relmse or --statistical"};
    if (!test_flag.empty() && !o.statistical)
        throw UsageError{test_flag + " sets the statistical test: give --statistical too (the thresholds do not read it)"};
    o.test = files[0];
    o.reference = files[1];
    if (o.diff) {
        const ImageFormatInfo* format = format_by_extension(*o.diff);
        if (!format || format->hdr)
            throw UsageError{"--diff writes an 8-bit picture: give it a name ending in .png or .ppm"};
        // The picture never replaces an image being compared.
        for (const std::string& input : files)
            if (same_file(*o.diff, input))
                throw UsageError{"--diff " + quoted_path(*o.diff) + " would overwrite the input " + quoted_path(input)};
    }
    return o;
}

// A file that could not be read or compared: one line, exit 1. Called in a catch block:
// running out of memory goes on to main(), which says what there was not enough memory for.
int failed(const std::exception& e) {
    if (dynamic_cast<const std::bad_alloc*>(&e) || dynamic_cast<const std::length_error*>(&e)) throw;
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
}

}  // namespace

const char* compare_usage() { return kCompareUsage; }
const char* psnr_usage() { return kPsnrUsage; }

int run_psnr(int argc, char** argv) {
    if (argc == 3 && (std::string(argv[2]) == "-h" || std::string(argv[2]) == "--help")) {
        std::fputs(kPsnrUsage, stdout);
        return 0;
    }
    if (argc != 4) {
        std::fprintf(stderr, "error: psnr needs two image files (OpenEXR, PFM, PPM or PNG)\n");
        return 2;
    }
    try {
        const InputImage test = load_input(argv[2]), reference = load_input(argv[3]);
        check_sizes(test, reference);
        if (test.hdr && reference.hdr) {
            const ImageErrors e = radiance_errors(test.radiance, reference.radiance);
            std::printf("rmse %.6g relmse %.6g\n", e.rmse, e.relmse);
        } else {
            std::printf("%.2f\n", psnr(test.rgb8, reference.rgb8));
        }
        return 0;
    } catch (const std::exception& e) {
        return failed(e);
    }
}

int run_compare(int argc, char** argv) {
    CompareOptions opt;
    try {
        opt = parse_compare(argc, argv);
    } catch (const UsageError& e) {
        return report_usage(e, kCompareUsage);
    }
    try {
        const InputImage test = load_input(opt.test), reference = load_input(opt.reference);
        check_sizes(test, reference);
        bool agree = true;
        std::string figures;
        char buf[256];
        auto add = [&](const char* text) { figures += figures.empty() ? text : std::string(", ") + text; };
        const ImageErrors errors = pair_errors(test, reference);
        const double db = psnr(test.rgb8, reference.rgb8);
        // One figure, then its threshold where one was given: "rmse 0.01 (max 0.02)".
        auto figure = [&](const char* name, const char* format, double value, const char* bound_name,
                          const std::optional<double>& bound, bool within) {
            std::snprintf(buf, sizeof buf, format, value);
            add((std::string(name) + " " + buf).c_str());
            if (!bound) return;
            agree &= within;
            std::snprintf(buf, sizeof buf, " (%s %g)", bound_name, *bound);
            figures += buf;
        };
        figure("psnr", "%.2f dB", db, "min", opt.min_psnr, opt.min_psnr && db >= *opt.min_psnr);
        figure("rmse", "%.4g", errors.rmse, "max", opt.max_rmse, opt.max_rmse && errors.rmse <= *opt.max_rmse);
        figure("relmse", "%.4g", errors.relmse, "max", opt.max_relmse,
               opt.max_relmse && errors.relmse <= *opt.max_relmse);
        std::optional<StatisticalResult> stats;
        if (opt.statistical) {
            for (const InputImage* in : {&test, &reference})
                if (!in->hdr)
                    throw std::runtime_error(quoted_path(in->name) + ": --statistical needs an OpenEXR render with its variance "
                                                        "layer; this is an 8-bit image");
            stats = statistical_compare(test.radiance, test.name, reference.radiance, reference.name, opt.stats);
            agree &= stats->agree;
            std::snprintf(buf, sizeof buf,
                          "max |z| %.2f (limit %.2f over %zu block tests; worst: %s of the %dx%d block at %d,%d), "
                          "chi2 %.1f (limit %.1f), alpha %g",
                          stats->max_abs_z, stats->z_limit, stats->tests,
                          stats->worst_channel == 0 ? "R" : stats->worst_channel == 1 ? "G" : "B",
                          stats->worst_size, stats->worst_size, stats->worst_x, stats->worst_y, stats->chi_square, stats->chi_square_limit, opt.stats.alpha);
            add(buf);
            // A denoised render is biased: its raw radiance was tested, and the line says so.
            for (const InputImage* in : {&test, &reference})
                if (&tested_radiance(in->radiance) == &in->radiance.raw && (in == &test || in->name != test.name))
                    add((show_user_text(in->name) + " is denoised: its raw.R/G/B tested").c_str());
        }
        if (opt.diff) {
            const Rgb8Image picture = stats ? false_colour(stats->pixel_z, test.rgb8.width, test.rgb8.height, stats->z_limit)
                                            : false_colour(errors.pixel_error, test.rgb8.width, test.rgb8.height,
                                                           [&] {
                                                               float worst = 0;
                                                               for (float e : errors.pixel_error) worst = std::max(worst, e);
                                                               return worst > 0 ? double(worst) : 1.0;
                                                           }());
            write_image(*opt.diff, picture);
        }
        std::printf("%s: %s vs %s: %s\n", agree ? "agree" : "DIFFER", show_user_text(opt.test).c_str(),
                    show_user_text(opt.reference).c_str(),
                    figures.c_str());
        return agree ? 0 : 1;
    } catch (const std::exception& e) {
        return failed(e);
    }
}

}  // namespace kr
