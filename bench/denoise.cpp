// docs/denoising.md's figures: the denoiser's error against a converged reference, raw and
// denoised, at several sample counts, and its cost.
//   keithray_bench_denoise cost [ROUNDS [SCENE [FINAL_ROUNDS]]]
//       each filter alone on scene 3's 4 spp estimates at 512x512 and 1920x1080 (medians of
//       ROUNDS runs of the a-trous filter, of at most FINAL_ROUNDS (3) of the final one;
//       OMP_NUM_THREADS sets the threads; KR_BENCH_PARAMS='key=value ...' the final filter's
//       parameters, as for tune)
//   keithray_bench_denoise error SIZE REFERENCE_SPP SPP,SPP,... SCENE.json...
//       each scene at SIZE x SIZE: a reference at REFERENCE_SPP (seed 99, exact light
//       sampling), then renders at each SPP (seed 1) raw and denoised by each filter (the
//       interactive a-trous and the final one): relMSE (luminance, over ref^2 + 0.01) and PSNR
//       of the sRGB-tone-mapped 8-bit images against the reference's. The relMSE is printed
//       twice: as measured, and less the reference's own noise (per pixel the variance of its
//       mean luminance over the same denominator, which the squared difference to an
//       independent reference carries on top of the image's own error: an estimate of the
//       error against the converged image, unbiased but for the denominator, which holds the
//       noisy reference; the same term is subtracted for every image).
//       With KR_BENCH_CACHE=DIR the renders are kept there as checkpoints and read back by a
//       later run with the same scene, size, spp and seed (the filters are all that reruns).
//       KR_BENCH_SEED=S renders the images at seed S instead of 1 (the reference stays at 99);
//       KR_BENCH_WORST=N lists the N pixels where the final filter adds the most relMSE to raw's.
//   keithray_bench_denoise tune SIZE REFERENCE_SPP SPP 'key=value ...'... -- SCENE.json...
//       the final filter with each variant of its parameters (NlmParams' field names) on the
//       renders at SPP: per scene its relMSE over raw's at 256 spp, per variant their
//       geometric mean, median and largest (the tuning set's figures; KR_BENCH_CACHE as above).
//   keithray_bench_denoise goals SIZE REFERENCE_SPP SCENE.json...
//       the goals per scene (see goals()): relMSE of the final filter at 16 spp against
//       raw at 256 and 1,024 spp, and against raw at the file's spp (KR_BENCH_MAX_FILE_SPP
//       caps it), and the ratios' medians; KR_BENCH_CACHE as for error.
//   keithray_bench_denoise dump SIZE REFERENCE_SPP SPP DIR SCENE.json...
//       for analysis, per scene DIR/NAME-KEY.f32 (float32 planes, row-major, channels
//       interleaved): the reference, raw, a-trous and final images at SPP, the feature
//       buffers, the depth and the variance of the raw mean; with
//       KR_BENCH_VARIANTS='NAME:key=value ...;NAME:...' also the final filter's image for each
//       variant of its parameters (KR_BENCH_CACHE as for error).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/file_write.h"
#include "core/image.h"
#include "render/aov.h"
#include "render/checkpoint.h"
#include "render/outputs.h"
#include "render/progressive.h"
#include "scene/load.h"

using namespace kr;

namespace {

struct Prepared {
    Scene scene;
    RenderScene rs;
    RenderSettings settings;
};

Prepared prepare(const std::string& file, int width, int height, bool exact_lights) {
    Prepared p;
    p.scene = load_scene_file(file).scene;
    p.scene.renderer.width = width;
    p.scene.renderer.height = height;
    p.rs = prepare_scene(p.scene);
    p.settings = RenderSettings::from_scene(p.scene.renderer);
    if (exact_lights) p.settings.light_sampling = LightSampling::cone;
    p.settings.allocation = Allocation::uniform;
    return p;
}

RenderState render(const Prepared& p, int spp, uint64_t seed, const std::string& cache_name = "") {
    RenderSettings s = p.settings;
    s.seed = seed;
    RenderState state(p.scene.renderer.width, p.scene.renderer.height);
    state.track_halves();  // as render --denoise does
    StopRule rule;
    rule.max_passes = spp;
    const char* dir = std::getenv("KR_BENCH_CACHE");
    std::filesystem::path cached;
    if (dir && *dir && !cache_name.empty()) {
        cached = std::filesystem::path(dir) / (cache_name + "-" + std::to_string(p.scene.renderer.width) + "-" +
                                               std::to_string(spp) + "-" + std::to_string(seed) + ".ckpt");
        const CheckpointKey key = checkpoint_key(p.scene, p.rs, s, rule);
        if (std::filesystem::exists(cached)) {
            decode_checkpoint(read_checkpoint_file(cached, key), cached, key, state);
            return state;
        }
        render_until(p.rs, s, state, rule);
        write_file_atomic(cached, encode_checkpoint(key, state));
        return state;
    }
    render_until(p.rs, s, state, rule);
    return state;
}

// The layers the product's paths read to develop a render with `options`' denoising, by either
// filter (outputs.h develop_reads: `render --denoise` and Save read the halves, the display
// the samples of a Whitted render), so that the figures are of the images users get.
unsigned denoise_reads(const DevelopOptions& options) {
    DevelopOptions interactive = options, final = options;
    interactive.interactive = true;
    final.interactive = false;
    return kLayerRadiance | develop_reads(interactive) | develop_reads(final);
}

double rel_mse(const Image& a, const Image& ref) {
    double sum = 0;
    for (size_t i = 0; i < ref.pixels.size(); ++i) {
        const double r = luminance(ref.pixels[i]), d = luminance(a.pixels[i]) - r;
        sum += d * d / (r * r + 0.01);
    }
    return sum / double(ref.pixels.size());
}

// rel_mse without the 0.1 % largest per-pixel terms (the goals' and the tuning's measure): a
// scene of glass under small bright lights has caustic paths that a unidirectional path
// tracer finds rarely, each a firefly hundreds of times its pixel's value, and a handful of
// them in one render (or in the reference) decide the plain mean. The same share is dropped
// from every image compared.
double rel_mse_trimmed(const Image& a, const Image& ref) {
    std::vector<double> terms(ref.pixels.size());
    for (size_t i = 0; i < ref.pixels.size(); ++i) {
        const double r = luminance(ref.pixels[i]), d = luminance(a.pixels[i]) - r;
        terms[i] = d * d / (r * r + 0.01);
    }
    const size_t keep = terms.size() - (terms.size() + 999) / 1000;
    std::nth_element(terms.begin(), terms.begin() + ptrdiff_t(keep), terms.end());
    double sum = 0;
    for (size_t i = 0; i < keep; ++i) sum += terms[i];
    return sum / double(keep);
}

// The reference's own share of rel_mse: per pixel the variance of its mean luminance over the
// same denominator (pixels of fewer than two samples count none).
double reference_noise(const RenderState& ref) {
    const Image mean = ref.radiance();
    double sum = 0;
    for (size_t i = 0; i < mean.pixels.size(); ++i) {
        const double se = ref.pixel_standard_error(i), r = luminance(mean.pixels[i]);
        if (std::isfinite(se)) sum += se * se / (r * r + 0.01);
    }
    return sum / double(mean.pixels.size());
}

double psnr_srgb(const Image& a, const Image& ref) {
    return psnr(tonemap(a, ToneMap::srgb, 1.0), tonemap(ref, ToneMap::srgb, 1.0));
}

// CPU seconds of the whole process (every thread): what the filter costs apart from waiting
// for a core on a shared machine.
double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    return (v[(v.size() - 1) / 2] + v[v.size() / 2]) / 2;
}

// The items of `text` between `separator`s, empty ones left out.
std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> items;
    size_t at = 0;
    while (at < text.size()) {
        size_t end = text.find(separator, at);
        if (end == std::string::npos) end = text.size();
        if (end > at) items.push_back(text.substr(at, end - at));
        at = end + 1;
    }
    return items;
}

// NlmParams from "key=value key=value ..." (defined below).
NlmParams parse_params(const std::string& text);

int cost(int rounds, const std::string& scene_file, int final_rounds) {
    final_rounds = std::min(rounds, final_rounds);
    for (const auto& [w, h] : {std::pair{512, 512}, std::pair{1920, 1080}}) {
        const Prepared p = prepare(scene_file, w, h, false);
        const RenderState state = render(p, 4, 1);
        RenderEstimates est = render_estimates(state, kAllLayers | kLayerHalves);  // the final filter's input
        feature_buffers(p.rs, p.settings, w, h, est.albedo, est.normal);
        const DenoiseInput in = denoise_input(est, est.radiance, true);
        std::vector<double> ms, cpu_ms, feature_ms, final_ms, final_cpu_ms;
        DenoiseWorkspace workspace;  // as the viewer keeps it
        for (int r = 0; r < rounds; ++r) {
            const double c0 = cpu_seconds();
            auto t0 = std::chrono::steady_clock::now();
            const Image out = denoise_atrous(in, {}, &workspace);
            auto t1 = std::chrono::steady_clock::now();
            cpu_ms.push_back(1e3 * (cpu_seconds() - c0));
            ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            if (out.pixels.empty()) return 1;
            if (r < final_rounds) {
                const double f0 = cpu_seconds();
                const auto s0 = std::chrono::steady_clock::now();
                const char* pv = std::getenv("KR_BENCH_PARAMS");
                const Image final = denoise_nlmeans(in, parse_params(pv ? pv : ""), &workspace);
                final_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s0).count());
                final_cpu_ms.push_back(1e3 * (cpu_seconds() - f0));
                if (final.pixels.empty()) return 1;
            }
            if (r < 3) {
                t0 = std::chrono::steady_clock::now();
                (void)averaged_surface_layers(p.rs, p.settings, w, h, kFeatureSamples);
                t1 = std::chrono::steady_clock::now();
                feature_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            }
        }
        std::printf("%dx%d: a-trous filter %.1f ms wall (median of %d; min %.1f), %.1f ms CPU (all threads; min %.1f); "
                    "feature buffers at %d samples %.1f ms wall; final filter %.0f ms wall (median of %d), %.0f ms CPU\n",
                    w, h, median(ms), rounds, *std::min_element(ms.begin(), ms.end()), median(cpu_ms),
                    *std::min_element(cpu_ms.begin(), cpu_ms.end()), kFeatureSamples, median(feature_ms),
                    median(final_ms), final_rounds, median(final_cpu_ms));
    }
    return 0;
}

// The pixels where the final filter adds the most to raw's relMSE (their share of the image's
// relMSE difference, and the raw mean's standard error): where a loss comes from.
void print_worst_pixels(const Developed& final, const Image& reference, const RenderState& state, int size, int count) {
    std::vector<std::pair<double, size_t>> added;
    double total = 0;
    for (size_t i = 0; i < reference.pixels.size(); ++i) {
        const double r = luminance(reference.pixels[i]);
        const double raw = luminance(final.raw.pixels[i]) - r, filtered = luminance(final.radiance.pixels[i]) - r;
        added.push_back({(filtered * filtered - raw * raw) / (r * r + 0.01) / double(reference.pixels.size()), i});
        total += added.back().first;
    }
    std::sort(added.rbegin(), added.rend());
    std::printf("  relMSE final - raw: %.6f; the %d pixels adding the most:\n", total, count);
    for (int j = 0; j < count && size_t(j) < added.size(); ++j) {
        const size_t i = added[size_t(j)].second;
        std::printf("  x %zu y %zu adds %.6f: reference %.4f raw %.4f (standard error %.4f) final %.4f\n",
                    i % size_t(size), i / size_t(size), added[size_t(j)].first, luminance(reference.pixels[i]),
                    luminance(final.raw.pixels[i]), state.pixel_standard_error(i), luminance(final.radiance.pixels[i]));
    }
}

int error(int size, int reference_spp, const std::vector<int>& spps, const std::vector<std::string>& scenes) {
    const char* seed_text = std::getenv("KR_BENCH_SEED");
    const char* worst_text = std::getenv("KR_BENCH_WORST");
    const uint64_t seed = seed_text && *seed_text ? std::stoull(seed_text) : 1;
    const int worst = worst_text && *worst_text ? std::stoi(worst_text) : 0;
    if (seed == 99) {
        std::fprintf(stderr, "keithray_bench_denoise: KR_BENCH_SEED 99 is the reference's seed\n");
        return 2;
    }
    std::printf("scene | spp | relMSE raw | relMSE a-trous | relMSE final | PSNR raw | PSNR a-trous | PSNR final | "
                "less the reference's noise: relMSE raw | a-trous | final\n");
    for (const std::string& file : scenes) {
        const Prepared p = prepare(file, size, size, true);
        const std::string name = std::filesystem::path(file).stem().string();
        const RenderState reference_state = render(p, reference_spp, 99, name);
        const Image reference = reference_state.radiance();
        const double ref_noise = reference_noise(reference_state);
        for (const int spp : spps) {
            const RenderState state = render(p, spp, seed, name);
            DevelopOptions options;
            options.denoise = Denoise::on;
            options.sampling = p.settings;
            options.sampling.seed = seed;
            const RenderEstimates estimates = render_estimates(state, denoise_reads(options));
            options.interactive = true;
            const Developed fast = develop(p.rs, estimates, options, kLayerRadiance);
            options.interactive = false;
            const Developed final = develop(p.rs, estimates, options, kLayerRadiance);
            const double raw = rel_mse(final.raw, reference), atrous = rel_mse(fast.radiance, reference),
                         filtered = rel_mse(final.radiance, reference);
            std::printf("%s | %d | %.5f | %.5f | %.5f | %.2f | %.2f | %.2f | %.5f | %.5f | %.5f\n", name.c_str(), spp, raw,
                        atrous, filtered, psnr_srgb(final.raw, reference), psnr_srgb(fast.radiance, reference),
                        psnr_srgb(final.radiance, reference), raw - ref_noise, atrous - ref_noise, filtered - ref_noise);
            std::fflush(stdout);
            if (worst > 0) print_worst_pixels(final, reference, state, size, worst);
        }
    }
    return 0;
}

// The goals per scene, at SIZE x SIZE against a reference at REFERENCE_SPP (seed 99,
// exact light sampling; the renders seed 1): relMSE (rel_mse_trimmed) of the final filter at
// 16 spp against raw at 256 and 1,024 spp, and of the final filter against raw at the file's
// own spp (at most MAX_FILE_SPP), as measured. Against an independent reference every figure carries the same
// reference noise on top of its own error (its estimate from the reference's per-pixel
// variance is printed): a comparison between two of them holds as it would against the
// converged image; the ratios are those of the measured figures (nearer 1 than those of the
// errors alone). The estimate is not subtracted: with rare bright paths (caustics through
// glass) the reference's variance is heavy-tailed, and less it a measured raw error can come
// out negative.
int goals(int size, int reference_spp, int max_file_spp, const std::vector<std::string>& scenes) {
    std::printf("relMSE without the 0.1 %% largest pixel terms\n"
                "scene | file spp | reference noise (est.) | final@16 | raw@256 | raw@1024 | final@16/raw@256 | "
                "final@16/raw@1024 | final@file | raw@file | final/raw@file\n");
    std::vector<double> r256, r1024, rfile;
    bool all256 = true, allfile = true;
    for (const std::string& file : scenes) {
        const Prepared p = prepare(file, size, size, true);
        const std::string name = std::filesystem::path(file).stem().string();
        const RenderState reference_state = render(p, reference_spp, 99, name);
        const Image reference = reference_state.radiance();
        // relMSE of the final filter's image and of the raw one at `spp`.
        const auto measured = [&](int spp) {
            const RenderState state = render(p, spp, 1, name);
            DevelopOptions options;
            options.denoise = Denoise::on;
            options.sampling = p.settings;
            options.sampling.seed = 1;
            const Developed out = develop(p.rs, render_estimates(state, denoise_reads(options)), options, kLayerRadiance);
            return std::pair{rel_mse_trimmed(out.radiance, reference), rel_mse_trimmed(out.raw, reference)};
        };
        const int file_spp = std::min(max_file_spp, int(p.scene.renderer.samples));
        const double final16 = measured(16).first, raw256 = measured(256).second, raw1024 = measured(1024).second;
        const auto [final_file, raw_file] = measured(file_spp);
        r256.push_back(final16 / raw256);
        r1024.push_back(final16 / raw1024);
        rfile.push_back(final_file / raw_file);
        all256 = all256 && final16 < raw256;
        allfile = allfile && final_file < raw_file;
        std::printf("%s | %d | %.5f | %.5f | %.5f | %.5f | %.2f | %.2f | %.5f | %.5f | %.2f\n", name.c_str(), file_spp,
                    reference_noise(reference_state), final16, raw256, raw1024, r256.back(), r1024.back(), final_file,
                    raw_file, rfile.back());
        std::fflush(stdout);
    }
    std::printf("median | | | | | | %.2f | %.2f | | | %.2f\n", median(r256), median(r1024), median(rfile));
    std::printf("final@16 below raw@256 on every scene: %s; median final@16/raw@1024 below 1: %s; final below raw at "
                "the file's spp on every scene: %s\n",
                all256 ? "yes" : "no", median(r1024) < 1 ? "yes" : "no", allfile ? "yes" : "no");
    return 0;
}

// Diagnostic planes for analysis (float32, row-major, interleaved channels): per scene
// DIR/NAME-KEY.f32 for the reference, raw, a-trous and final at SPP, the feature buffers,
// the depth and the variance of the raw mean.
int dump(int size, int reference_spp, int spp, const std::string& dir, const std::vector<std::string>& scenes) {
    std::filesystem::create_directories(dir);
    for (const std::string& file : scenes) {
        const Prepared p = prepare(file, size, size, true);
        const std::string name = std::filesystem::path(file).stem().string();
        const RenderState reference_state = render(p, reference_spp, 99, name);
        const RenderState state = render(p, spp, 1, name);
        DevelopOptions options;
        options.denoise = Denoise::on;
        options.sampling = p.settings;
        options.sampling.seed = 1;
        RenderEstimates estimates = render_estimates(state, denoise_reads(options));
        feature_buffers(p.rs, options.sampling, size, size, estimates.albedo, estimates.normal);
        options.interactive = true;
        const Developed fast = develop(p.rs, estimates, options, kLayerRadiance);
        options.interactive = false;
        const Developed final = develop(p.rs, estimates, options, kLayerRadiance);
        const auto put = [&](const std::string& key, const std::vector<float>& v) {
            const std::string bytes(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(float));
            write_file_atomic(std::filesystem::path(dir) / (name + "-" + key + ".f32"), bytes);
        };
        const auto colors = [](const Image& im) {
            std::vector<float> v;
            for (const Color& c : im.pixels) v.insert(v.end(), {float(c.x), float(c.y), float(c.z)});
            return v;
        };
        if (const char* variants = std::getenv("KR_BENCH_VARIANTS"))
            for (const std::string& item : split(variants, ';')) {
                const size_t colon = item.find(':');
                const DenoiseInput in = denoise_input(estimates, estimates.radiance, true);
                put(item.substr(0, colon), colors(denoise_nlmeans(in, parse_params(item.substr(colon + 1)))));
            }
        put("ref", colors(reference_state.radiance()));
        put("raw", colors(final.raw));
        put("final", colors(final.radiance));
        put("atrous", colors(fast.radiance));
        put("albedo", estimates.albedo);
        put("normal", estimates.normal);
        std::vector<float> depth(estimates.depth.begin(), estimates.depth.end()), variance;
        for (const Color& c : estimates.variance) variance.insert(variance.end(), {float(c.x), float(c.y), float(c.z)});
        put("depth", depth);
        put("var", variance);
        std::printf("%s written\n", name.c_str());
    }
    return 0;
}

// NlmParams from "key=value key=value ..." over the defaults: the names of its fields, and k1
// .. k3, n1 .. n3 for the candidates' distance scales and normal stops, `candidates` for
// their count.
NlmParams parse_params(const std::string& text) {
    NlmParams params;
    for (const std::string& item : split(text, ' ')) {
        const size_t eq = item.find('=');
        if (eq == std::string::npos) throw std::invalid_argument("parameter '" + item + "' has no '='");
        const std::string key = item.substr(0, eq);
        const double value = std::stod(item.substr(eq + 1));
        if (key == "radius") params.radius = int(value);
        else if (key == "patch") params.patch = int(value);
        else if (key.size() == 2 && (key[0] == 'k' || key[0] == 'n') && key[1] >= '1' &&
                 key[1] < '1' + kMaxNlmCandidates) {
            // k1 .. k3, n1 .. n3: candidate 1 .. 3's distance scale and normal stop
            NlmCandidate& c = params.candidates[key[1] - '1'];
            (key[0] == 'k' ? c.k : c.sigma_normal) = float(value);
        } else if (key == "candidates") params.candidate_count = int(value);
        else if (key == "select_radius") params.select_radius = int(value);
        else if (key == "own_error_stop") params.own_error_stop = float(value);
        else if (key == "sigma_albedo") params.sigma_albedo = float(value);
        else if (key == "sigma_depth") params.sigma_depth = float(value);
        else if (key == "fade_error") params.fade_error = float(value);
        else throw std::invalid_argument("unknown parameter '" + key + "'");
    }
    return params;
}

// Parameter variants of the final filter on the cached renders (tuning): per scene and
// variant the relMSE of the final filter at SPP over raw's at 256 spp, then per variant the
// geometric mean and the largest of those ratios.
int tune(int size, int reference_spp, int spp, const std::vector<std::string>& variants,
         const std::vector<std::string>& scenes) {
    std::vector<std::vector<double>> ratios(variants.size());
    for (const std::string& file : scenes) {
        const Prepared p = prepare(file, size, size, true);
        const std::string name = std::filesystem::path(file).stem().string();
        const Image reference = render(p, reference_spp, 99, name).radiance();
        const double raw256 = rel_mse_trimmed(render(p, 256, 1, name).radiance(), reference);
        const RenderState state = render(p, spp, 1, name);
        RenderEstimates est = render_estimates(state, kAllLayers | kLayerHalves);  // the final filter's input
        RenderSettings sampling = p.settings;
        sampling.seed = 1;
        feature_buffers(p.rs, sampling, size, size, est.albedo, est.normal);
        const DenoiseInput in = denoise_input(est, est.radiance, true);
        std::printf("%s", name.c_str());
        for (size_t v = 0; v < variants.size(); ++v) {
            const Image den = denoise_nlmeans(in, parse_params(variants[v]));
            ratios[v].push_back(rel_mse_trimmed(den, reference) / raw256);
            std::printf(" | %.3f", ratios[v].back());
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    for (size_t v = 0; v < variants.size(); ++v) {
        double log_sum = 0;
        for (const double r : ratios[v]) log_sum += std::log(r);
        std::printf("'%s': geometric mean %.3f, median %.3f, largest %.3f\n", variants[v].c_str(),
                    std::exp(log_sum / double(ratios[v].size())), median(ratios[v]),
                    *std::max_element(ratios[v].begin(), ratios[v].end()));
    }
    return 0;
}

}  // namespace

int run(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "cost")
        return cost(argc > 2 ? std::stoi(argv[2]) : 15, argc > 3 ? argv[3] : "res/scenes/assignment_03.json",
                    argc > 4 ? std::stoi(argv[4]) : 3);
    if (mode == "error" && argc > 5) {
        std::vector<int> spps;
        for (const std::string& spp : split(argv[4], ',')) spps.push_back(std::stoi(spp));
        return error(std::stoi(argv[2]), std::stoi(argv[3]), spps, std::vector<std::string>(argv + 5, argv + argc));
    }
    if (mode == "tune" && argc > 5) {
        // tune SIZE REFERENCE_SPP SPP 'VARIANT' ... -- SCENE...
        std::vector<std::string> variants, scenes;
        bool after = false;
        for (int a = 5; a < argc; ++a) {
            const std::string arg = argv[a];
            if (arg == "--") after = true;
            else (after ? scenes : variants).push_back(arg);
        }
        return tune(std::stoi(argv[2]), std::stoi(argv[3]), std::stoi(argv[4]), variants, scenes);
    }
    if (mode == "dump" && argc > 6)
        return dump(std::stoi(argv[2]), std::stoi(argv[3]), std::stoi(argv[4]), argv[5],
                    std::vector<std::string>(argv + 6, argv + argc));
    if (mode == "goals" && argc > 4)
        return goals(std::stoi(argv[2]), std::stoi(argv[3]), std::getenv("KR_BENCH_MAX_FILE_SPP")
                                                                 ? std::stoi(std::getenv("KR_BENCH_MAX_FILE_SPP"))
                                                                 : 1 << 30,
                     std::vector<std::string>(argv + 4, argv + argc));
    std::fprintf(stderr,
                 "usage: keithray_bench_denoise cost [ROUNDS [SCENE [FINAL_ROUNDS]]] | error SIZE REFERENCE_SPP SPP,SPP,... SCENE... "
                 "| goals SIZE REFERENCE_SPP SCENE... | tune SIZE REFERENCE_SPP SPP VARIANT... -- SCENE... "
                 "| dump SIZE REFERENCE_SPP SPP DIR SCENE...\n");
    return 2;
}

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "keithray_bench_denoise: %s\n", e.what());
        return 2;
    }
}
