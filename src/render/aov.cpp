#include "render/aov.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "render/material.h"
#include "render/path.h"
#include "render/trace.h"

namespace kr {

FirstSurface first_surface(const RenderScene& scene, Ray ray, int max_chain) {
    Hit hit;
    scene.intersects(ray, hit);
    return first_surface_from(scene, ray, hit, max_chain);
}

FirstSurface first_surface_from(const RenderScene& scene, Ray ray, Hit hit, int max_chain) {
    FirstSurface out;
    Color tint(1.0);
    for (int chain = 0; chain <= max_chain; ++chain) {
        if (chain > 0) {
            hit = Hit();
            scene.intersects(ray, hit);
        }
        if (hit.sphere < 0) break;
        const Material& m = scene.materials[size_t(scene.sphere_material[size_t(hit.sphere)])];
        const SurfacePoint sp{hit.n, dot(ray.d, hit.n) < 0};
        // Delta lobes are followed: a mirror reflects, a sharp dielectric refracts
        // unless it totally reflects (by the material's lobes, vertex.inc).
        const vertex::MaterialLobes lobes = vertex::material_lobes(m.type);
        if (!lobes.smooth && !lobes.rough) {
            Vec3 next;
            if (!lobes.fresnel_split) {
                next = ray.d - 2 * dot(ray.d, sp.ns()) * sp.ns();
                tint *= m.rho;
            } else {
                const DielectricSplit split = split_dielectric(m, sp, ray.d);
                const bool reflect = split.reflectance >= 1;
                next = reflect ? split.reflected : split.transmitted;
                tint *= reflect ? m.rho_r : m.rho_t;
            }
            respawn(ray, hit, normalize(next));
            continue;
        }
        Color albedo = m.rho;
        if (lobes.fresnel_split) {
            const double r = split_dielectric(m, sp, ray.d).reflectance;
            albedo = m.rho_r * r + m.rho_t * (1 - r);
        }
        out.albedo = tint * albedo;
        out.normal = sp.ns();
        out.hit = true;
        break;
    }
    return out;
}

SurfaceLayers first_surface_layers(const RenderScene& scene, int width, int height, int max_chain) {
    SurfaceLayers out;
    const size_t n = size_t(width) * size_t(height);
    out.albedo.assign(n, Color());
    out.normal.assign(n, Color());
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // The pixel centre under the references' raster convention, through the lens centre.
            const Vec2 film = raster_to_camera(x + 0.5, y + 0.5, width, height);
            const CameraRay cr = scene.camera.generate(film.x, film.y, 0.5, 0.5);
            Ray ray;
            ray.o = cr.origin;
            ray.d = cr.direction;
            const FirstSurface s = first_surface(scene, ray, max_chain);
            const size_t i = size_t(y) * size_t(width) + size_t(x);
            out.albedo[i] = s.albedo;
            out.normal[i] = s.normal;
        }
    return out;
}

SurfaceLayers averaged_surface_layers(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                                      int samples) {
    samples = std::clamp(samples, 1, kSampleBatch);
    SurfaceLayers out;
    add_surface_samples(scene, settings, width, height, 0, samples, out);
    const double inverse = 1.0 / double(samples);
    for (size_t i = 0; i < out.albedo.size(); ++i) {
        out.albedo[i] = out.albedo[i] * inverse;
        out.normal[i] = out.normal[i] * inverse;
    }
    return out;
}

namespace {

// Adds to `sums` the first-surface layers of the camera samples [first, first + count) of each
// pixel of `box` whose `range` gives them (pixel index) -> {first, count}. A row's samples go
// in batches of kSampleBatch (the camera rays made together, in the lanes); each pixel's are
// added in order of their index, so the sums are the same in any number of calls.
template <class Range>
void add_box_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                     const PixelBox& box, SurfaceLayers& sums, const Range& range,
                     const std::atomic<bool>* cancel = nullptr) {
    const bool sobol = settings.estimator == Estimator::sobol;
    const LaneKernels kernels = casting_kernels(scene, settings);
#pragma omp parallel
    {
        std::vector<std::optional<Sampler>> samplers(kSampleBatch);
        std::vector<Sampler*> pointers(kSampleBatch);
        std::vector<int> xs(kSampleBatch), ys(kSampleBatch), spheres(kSampleBatch);
        std::vector<uint32_t> indices(kSampleBatch), keys(kSampleBatch), reversed(kSampleBatch);
        std::vector<size_t> pixels(kSampleBatch);
        std::vector<Ray> rays(kSampleBatch);
        std::vector<Hit> hits(kSampleBatch);
        std::vector<float> normals(3 * size_t(kSampleBatch));
        int pending = 0;
        const auto add = [&](int k, const Color& albedo, const Color& normal) {
            sums.albedo[pixels[size_t(k)]] += albedo;
            sums.normal[pixels[size_t(k)]] += normal;
        };
        const auto flush = [&] {
            if (pending == 0) return;
            // Sobol samples in the float lanes where they apply: their rays made and cast there,
            // a diffuse or glossy first surface taken whole; one that is followed (a mirror or
            // glass) or split by Fresnel, one by one from its ray.
            if (sobol && camera_surfaces(kernels, scene, width, height, xs.data(), ys.data(), keys.data(),
                                         reversed.data(), pending, spheres.data(), normals.data())) {
                for (int k = 0; k < pending; ++k) {
                    const int sphere = spheres[size_t(k)];
                    if (sphere < 0) continue;  // nothing: zero layers
                    const Material& m = scene.materials[size_t(scene.sphere_material[size_t(sphere)])];
                    const vertex::MaterialLobes lobes = vertex::material_lobes(m.type);
                    if ((lobes.smooth || lobes.rough) && !lobes.fresnel_split) {
                        const float* n = &normals[3 * size_t(k)];
                        const Color normal(n[0], n[1], n[2]);
                        add(k, m.rho, normal / length(normal));  // unit in double, as one path's
                        continue;
                    }
                    // The ray in double, its first hit on the lanes' sphere.
                    Sampler sampler(keys[size_t(k)], indices[size_t(k)], reversed[size_t(k)]);
                    const Ray ray = camera_ray(scene, width, height, xs[size_t(k)], ys[size_t(k)], sampler);
                    const FirstSurface s = first_surface_from(scene, ray, lanes_sphere_hit(scene, ray, sphere));
                    add(k, s.albedo, s.normal);
                }
                pending = 0;
                return;
            }
            for (int k = 0; k < pending; ++k)
                pointers[size_t(k)] =
                    sobol ? &samplers[size_t(k)].emplace(keys[size_t(k)], indices[size_t(k)], reversed[size_t(k)])
                          : &samplers[size_t(k)].emplace(settings.estimator, settings.seed, pixels[size_t(k)],
                                                         indices[size_t(k)], settings.target_spp);
            camera_rays(scene, settings, width, height, xs.data(), ys.data(), pointers.data(), pending, rays.data());
            camera_hits(kernels, scene, rays.data(), pending, hits.data());
            for (int k = 0; k < pending; ++k) {
                const FirstSurface s = first_surface_from(scene, rays[size_t(k)], hits[size_t(k)]);
                add(k, s.albedo, s.normal);
            }
            pending = 0;
        };
#pragma omp for schedule(dynamic, 4)
        for (int y = box.y0; y < box.y1; ++y) {
            if (cancel && cancel->load(std::memory_order_relaxed)) continue;  // rows not begun: untouched
            for (int x = box.x0; x < box.x1; ++x) {
                const size_t pixel = size_t(y) * size_t(width) + size_t(x);
                const auto [first, count] = range(pixel);
                // The pixel's camera samples first..first+count-1, made as render_pass makes them.
                const uint32_t key = sobol ? Sampler::pixel_key(settings.seed, pixel) : 0;
                for (int k = 0; k < count; ++k) {
                    if (pending == kSampleBatch) flush();
                    const uint32_t index = uint32_t(first + k);
                    const size_t slot = size_t(pending++);
                    indices[slot] = index;
                    keys[slot] = key;
                    reversed[slot] = reverse_bits(index);
                    xs[slot] = x;
                    ys[slot] = y;
                    pixels[slot] = pixel;
                }
            }
            flush();  // a row's samples all added before the next row's (rows go to threads)
        }
    }
}

void size_sums(size_t n, SurfaceLayers& sums) {
    if (sums.albedo.size() != n || sums.normal.size() != n) {
        sums.albedo.assign(n, Color());
        sums.normal.assign(n, Color());
    }
}

}  // namespace

void add_surface_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height, int first,
                         int count, SurfaceLayers& sums) {
    size_sums(size_t(width) * size_t(height), sums);
    first = std::max(0, first);
    count = std::clamp(count, 0, kSampleBatch);
    if (count == 0) return;
    add_box_samples(scene, settings, width, height, PixelBox{0, 0, width, height}, sums,
                    [&](size_t) { return std::pair{first, count}; });
}

bool add_surface_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                         const PixelBox& box, int total, std::vector<uint8_t>& counts, SurfaceLayers& sums,
                         const std::atomic<bool>* cancel) {
    const size_t n = size_t(width) * size_t(height);
    size_sums(n, sums);
    if (counts.size() != n) counts.assign(n, 0);
    const PixelBox inside{std::max(0, box.x0), std::max(0, box.y0), std::min(width, box.x1), std::min(height, box.y1)};
    if (inside.x0 >= inside.x1 || inside.y0 >= inside.y1) return true;
    total = std::clamp(total, 0, kSampleBatch);
    add_box_samples(
        scene, settings, width, height, inside, sums,
        [&](size_t pixel) {
            const int first = counts[pixel];
            counts[pixel] = uint8_t(std::max(first, total));  // each pixel's own entry: no race
            return std::pair{first, total - first};
        },
        cancel);
    return !(cancel && cancel->load());
}

}  // namespace kr
