#include "render/outputs.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

#include "core/image_hdr.h"
#include "core/image_io.h"
#include "render/aov.h"

namespace kr {

namespace {

std::vector<float> floats(const std::vector<Color>& values) {
    std::vector<float> out(3 * values.size());
    for (size_t i = 0; i < values.size(); ++i)
        for (int k = 0; k < 3; ++k) out[3 * i + size_t(k)] = stored_float(values[i][k]);
    return out;
}

// The layers worth making for an output: the format's, less the variance of a blurred image.
unsigned layers_for(const OutputRequest& request) {
    const unsigned layers = output_format(request.path).layers;
    return request.develop.blur > 0 ? layers & ~unsigned(kLayerVariance) : layers;
}

// The mean samples per pixel (1 where the estimates carry no counts: a preview).
double mean_samples(const std::vector<uint32_t>& samples) {
    if (samples.empty()) return 1;
    double sum = 0;
    for (const uint32_t n : samples) sum += n;
    return sum / double(samples.size());
}

}  // namespace

RenderEstimates render_estimates(const Film& film, unsigned layers) {
    RenderEstimates out;
    if (layers & kLayerRadiance) out.radiance = film.radiance();
    if (layers & kLayerDepth) out.depth = film.mean_depth();
    if (layers & kLayerSamples) out.samples = film.sample_count();
    if (layers & kLayerVariance) out.variance = film.variance_of_mean();
    if ((layers & kLayerHalves) && film.tracks_halves()) out.halves = film.halves();
    return out;
}

void feature_buffers(const RenderScene& scene, const RenderSettings& sampling, int width, int height,
                     std::vector<float>& albedo, std::vector<float>& normal) {
    SurfaceLayers sums;
    add_surface_samples(scene, sampling, width, height, 0, kFeatureSamples, sums);
    feature_buffers_from_sums(sums, kFeatureSamples, albedo, normal);
}

namespace {

// Pixel i's feature buffers: its sums over `samples` camera samples, averaged as
// averaged_surface_layers averages them (times the reciprocal).
void feature_pixel(const SurfaceLayers& sums, size_t i, int samples, std::vector<float>& albedo,
                   std::vector<float>& normal) {
    const double inverse = 1.0 / double(std::max(1, samples));
    for (int k = 0; k < 3; ++k) {
        albedo[3 * i + size_t(k)] = stored_float(sums.albedo[i][k] * inverse);
        normal[3 * i + size_t(k)] = stored_float(sums.normal[i][k] * inverse);
    }
}

}  // namespace

void feature_buffers_from_sums(const SurfaceLayers& sums, int samples, std::vector<float>& albedo,
                               std::vector<float>& normal) {
    const size_t n = sums.albedo.size();
    albedo.resize(3 * n);
    normal.resize(3 * n);
    for (size_t i = 0; i < n; ++i) feature_pixel(sums, i, samples, albedo, normal);
}

void feature_buffers_from_sums(const SurfaceLayers& sums, const std::vector<uint8_t>& counts, int width,
                               const PixelBox& box, std::vector<float>& albedo, std::vector<float>& normal) {
    const size_t n = sums.albedo.size();
    albedo.resize(3 * n);
    normal.resize(3 * n);
    const int height = width > 0 ? int(n / size_t(width)) : 0;
    for (int y = std::max(0, box.y0); y < std::min(height, box.y1); ++y)
        for (int x = std::max(0, box.x0); x < std::min(width, box.x1); ++x) {
            const size_t i = size_t(y) * size_t(width) + size_t(x);
            feature_pixel(sums, i, counts[i], albedo, normal);
        }
}

DenoiseInput denoise_input(const RenderEstimates& estimates, const Image& radiance, bool with_halves) {
    DenoiseInput input;
    input.radiance = &radiance;
    input.variance = estimates.variance;
    input.albedo = estimates.albedo;
    input.normal = estimates.normal;
    input.depth = estimates.depth;
    if (with_halves)
        for (int h = 0; h < 2; ++h) {
            input.half[h] = &estimates.halves.mean[h];
            input.half_count[h] = estimates.halves.count[h];
        }
    return input;
}

Image denoised_image(const RenderEstimates& estimates, const Image& radiance, const DevelopOptions& options) {
    // The halves are of the unblurred mean: a blurred image is filtered without them.
    const DenoiseInput input = denoise_input(estimates, radiance, options.blur == 0);
    // A Whitted render's only noise is the pixel's anti-aliasing, whose error falls about
    // as 1/spp: the final filter would only soften its edges (docs/denoising.md), and the
    // interactive one helps only its first passes, so both keep the raw image from
    // kWhittedRawSpp samples per pixel on.
    const bool whitted_raw = options.sampling.integrator == Integrator::wrt &&
                             (!options.interactive || mean_samples(estimates.samples) >= kWhittedRawSpp);
    return whitted_raw           ? radiance
           : options.interactive ? denoise_atrous(input, {}, options.workspace, options.cancel)
                                 : denoise_nlmeans(input, {}, options.workspace);
}

unsigned develop_reads(const DevelopOptions& options) {
    if (options.denoise == Denoise::off) return 0;
    // The interactive filter leaves a Whitted render raw past its first passes: it counts them.
    const bool counts = options.interactive && options.sampling.integrator == Integrator::wrt;
    // The final filter reads the two halves of the samples; the interactive one does not.
    return unsigned(kLayerDepth | kLayerVariance) | (counts ? unsigned(kLayerSamples) : 0u) |
           (options.interactive ? 0u : unsigned(kLayerHalves));
}

Developed develop(const RenderScene& scene, RenderEstimates estimates, const DevelopOptions& options,
                  unsigned layers) {
    Developed out;
    const int width = estimates.radiance.width, height = estimates.radiance.height;
    out.radiance = options.blur > 0 ? box_blur(estimates.radiance, options.blur) : std::move(estimates.radiance);
    if (options.denoise != Denoise::off) {
        if (estimates.albedo.empty() || estimates.normal.empty())
            feature_buffers(scene, options.sampling, width, height, estimates.albedo, estimates.normal);
        Image denoised = denoised_image(estimates, out.radiance, options);
        out.raw = std::exchange(out.radiance, std::move(denoised));
        // An output with first-surface layers keeps the feature buffers the denoiser read.
        if (layers & kLayerAlbedo) out.albedo = std::move(estimates.albedo);
        if (layers & kLayerNormal) out.normal = std::move(estimates.normal);
    }
    if (layers & kLayerDepth) out.depth = std::move(estimates.depth);
    if (layers & kLayerSamples) out.samples = std::move(estimates.samples);
    // The variance belongs to the mean, not to its blurred picture.
    if ((layers & kLayerVariance) && options.blur == 0) out.variance = floats(estimates.variance);
    if ((layers & (kLayerAlbedo | kLayerNormal)) && options.denoise == Denoise::off) {
        const SurfaceLayers surface = first_surface_layers(scene, width, height);
        if (layers & kLayerAlbedo) out.albedo = floats(surface.albedo);
        if (layers & kLayerNormal) out.normal = floats(surface.normal);
    }
    return out;
}

HdrImage hdr_from_developed(Developed image) {
    HdrImage out = hdr_from_radiance(image.radiance);
    out.depth = stored_floats(image.depth);
    out.albedo = std::move(image.albedo);
    out.normal = std::move(image.normal);
    out.samples = std::move(image.samples);
    out.variance = std::move(image.variance);
    // Infinite marks a variance unknown for want of samples. A pixel of 2 samples or more has
    // one only where its squares overflowed a double (radiance above ~1e154): a variance far
    // beyond float's range, stored as its largest, as its mean is.
    if (out.samples.size() == out.pixel_count() && out.variance.size() == 3 * out.pixel_count())
        for (size_t i = 0; i < out.samples.size(); ++i)
            if (out.samples[i] >= 2)
                for (size_t k = 3 * i; k < 3 * i + 3; ++k)
                    if (out.variance[k] == std::numeric_limits<float>::infinity())
                        out.variance[k] = std::numeric_limits<float>::max();
    if (!image.raw.pixels.empty()) out.raw = floats(image.raw.pixels);
    return out;
}

std::vector<FileOutput> encode_outputs(const std::filesystem::path& path, Developed image,
                                       const DisplaySettings& display, const ToneMapper& tone_map) {
    const ImageFormatInfo& format = output_format(path);
    const int width = image.radiance.width, height = image.radiance.height;
    if (format.depth_beside && image.depth.size() != image.radiance.pixels.size())
        throw std::invalid_argument("encode_outputs: " + std::string(format.name) + " output without its depth layer");
    std::vector<FileOutput> files;
    const std::filesystem::path depth_file = depth_path_for(path);
    switch (format.format) {
    case ImageFormat::ppm:
    case ImageFormat::png: {
        const auto encode = format.format == ImageFormat::png ? encode_png : encode_ppm;
        const Rgb8Image shown = tone_map ? tone_map(image.radiance, display)
                                         : tonemap(image.radiance, display.tonemap, display.exposure_scale());
        files.push_back({path, encode(shown)});
        files.push_back({depth_file, encode(depth_to_rgb8(image.depth, width, height))});
        break;
    }
    case ImageFormat::exr:
        files.push_back({path, encode_exr(hdr_from_developed(std::move(image)))});
        break;
    case ImageFormat::pfm:
        files.push_back({path, encode_pfm_rgb(hdr_from_radiance(image.radiance))});
        files.push_back({depth_file, encode_pfm_gray(stored_floats(image.depth),
                                                     width, height)});
        break;
    }
    return files;
}

std::vector<FileOutput> output_files(const RenderScene& scene, RenderEstimates estimates, const OutputRequest& request) {
    return encode_outputs(request.path, develop(scene, std::move(estimates), request.develop, layers_for(request)),
                          request.display, request.tone_map);
}

std::vector<FileOutput> output_files(const RenderScene& scene, const RenderState& state, const OutputRequest& request) {
    return output_files(scene, render_estimates(state, layers_for(request) | develop_reads(request.develop)), request);
}

uint64_t render_memory_bytes(int width, int height, bool blurred, bool denoised) {
    const uint64_t eight_bit = 2 * 3 + 2 * 3, exr = 2 * 14 * sizeof(float);
    uint64_t output = sizeof(Color) * (blurred ? 3 : 1) + sizeof(double) + std::max(eight_bit, exr);
    if (denoised) output += kHalvesBytesPerPixel + kDenoiseBytesPerPixel;
    return uint64_t(width) * uint64_t(height) * (kRenderStateBytesPerPixel + output);
}

}  // namespace kr
