#include "viewer/reproject.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/trace.h"

namespace kr::viewer {

namespace {

// Pixel (x, y)'s centre ray: the camera's image point (x / width, (y + 1) / height), as
// raster_to_camera puts the centre (x + 1/2, y + 1/2) of the pixel's square.
CameraRay centre_ray(const CameraModel& camera, int width, int height, int x, int y) {
    const Vec2 film = raster_to_camera(x + 0.5, y + 0.5, width, height);
    return camera.generate(film.x, film.y, 0.5, 0.5);
}

// Whether pixel (x, y)'s four neighbours see the sphere its centre sees: away from a
// silhouette, where a pixel's colour mixes two surfaces.
bool inner_pixel(const ViewHits& view, int x, int y) {
    const int sphere = view.sphere[size_t(y) * size_t(view.width) + size_t(x)];
    for (const auto& [dx, dy] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
        const int nx = x + dx, ny = y + dy;
        if (nx >= 0 && ny >= 0 && nx < view.width && ny < view.height &&
            view.sphere[size_t(ny) * size_t(view.width) + size_t(nx)] != sphere)
            return false;
    }
    return true;
}

}  // namespace

ViewHits view_hits(const RenderScene& scene, int width, int height, const RenderSettings& settings,
                   const std::atomic<bool>* cancel) {
    ViewHits out;
    out.width = width;
    out.height = height;
    out.camera = scene.camera;
    const size_t n = size_t(width) * size_t(height);
    out.sphere.assign(n, -1);
    out.distance.assign(n, std::numeric_limits<float>::infinity());
    const LaneKernels kernels = casting_kernels(scene, settings);
#pragma omp parallel
    {
        std::vector<Ray> rays(size_t(std::max(width, 0)));
        std::vector<Hit> hits(rays.size());
#pragma omp for schedule(dynamic, 4)
        for (int y = 0; y < height; ++y) {
            if (cancel && cancel->load(std::memory_order_relaxed)) continue;
            for (int x = 0; x < width; ++x) {
                const CameraRay cr = centre_ray(scene.camera, width, height, x, y);
                rays[size_t(x)] = Ray();
                rays[size_t(x)].o = cr.origin;
                rays[size_t(x)].d = cr.direction;
            }
            camera_hits(kernels, scene, rays.data(), width, hits.data());
            for (int x = 0; x < width; ++x) {
                const Hit& hit = hits[size_t(x)];
                if (hit.sphere < 0) continue;
                const size_t i = size_t(y) * size_t(width) + size_t(x);
                out.sphere[i] = hit.sphere;
                out.distance[i] = float(hit.t);
            }
        }
    }
    return out;
}

std::optional<Vec2> project_to_pixel(const CameraModel& camera, int width, int height, const Vec3& point) {
    // The pinhole's film coordinates (pinhole_direction's, inverted), then the raster's.
    const Vec3 d = point - camera.position;
    const double depth = dot(d, camera.forward);
    if (!(depth > 0)) return std::nullopt;
    const double px = dot(d, camera.right) / depth, py = dot(d, camera.up) / depth;
    const double fx = 0.5 * (px / (camera.tan_half_fov * camera.aspect) + 1), fy = 0.5 * (1 - py / camera.tan_half_fov);
    // raster_to_camera: fx = (X - 1/2) / width, fy = (Y + 1/2) / height, and pixel i's centre is X = i + 1/2.
    return Vec2{fx * width, fy * height - 1};
}

Reprojection reproject(const RenderScene& scene, const ViewHits& now, const ViewHistory& history,
                       const std::atomic<bool>* cancel) {
    const int w = now.width, h = now.height;
    const ViewHits& before = history.hits;
    Reprojection out;
    out.colour = Image(w, h);
    out.weight.assign(size_t(w) * size_t(h), 0.0f);
    // A diffuse surface sends the same radiance every way: only there is the earlier view's
    // colour this view's.
    auto diffuse = [&](int sphere) {
        return scene.materials[size_t(scene.sphere_material[size_t(sphere)])].type == MaterialType::diffuse;
    };
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < h; ++y) {
        if (cancel && cancel->load(std::memory_order_relaxed)) continue;
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const int sphere = now.sphere[i];
            if (sphere < 0 || !diffuse(sphere)) continue;
            // Not on a silhouette: the pixel's samples there see another surface too.
            if (!inner_pixel(now, x, y)) continue;
            // The surface point, and where it lands in the earlier view.
            const CameraRay cr = centre_ray(now.camera, w, h, x, y);
            const Vec3 point = cr.origin + cr.direction * double(now.distance[i]);
            const auto at = project_to_pixel(before.camera, before.width, before.height, point);
            if (!at) continue;
            // The four pixels about it (at the image's last row or column, the two last ones:
            // a point within rounding of a pixel centre there is that centre).
            constexpr double kSlack = 1e-3;
            if (!(at->x >= -kSlack && at->y >= -kSlack && at->x <= before.width - 1 + kSlack &&
                  at->y <= before.height - 1 + kSlack))
                continue;
            const int left = std::clamp(int(std::floor(at->x)), 0, before.width - 2);
            const int top = std::clamp(int(std::floor(at->y)), 0, before.height - 2);
            const double fx = std::clamp(at->x - left, 0.0, 1.0), fy = std::clamp(at->y - top, 0.0, 1.0);
            // Seen there: the four pixels around it saw this sphere first, away from its
            // silhouette, at the point's distance (within what their own spread and 1 % allow),
            // not its far side or something in front of it.
            const double expected = length(point - before.camera.position);
            double lo = std::numeric_limits<double>::infinity(), hi = 0, along = 0, total = 0;
            float worth = std::numeric_limits<float>::infinity();
            Color colour;
            bool seen = true;
            for (int k = 0; k < 4 && seen; ++k) {
                const int tx = left + (k & 1), ty = top + (k >> 1);
                const size_t j = size_t(ty) * size_t(before.width) + size_t(tx);
                const double weight = (k & 1 ? fx : 1 - fx) * (k >> 1 ? fy : 1 - fy);
                if (weight < 1e-9) continue;  // a pixel the point is not near has no say
                seen = before.sphere[j] == sphere && inner_pixel(before, tx, ty);
                lo = std::min(lo, double(before.distance[j]));
                hi = std::max(hi, double(before.distance[j]));
                along += weight * double(before.distance[j]);
                total += weight;
                colour += history.picture.pixels[j] * weight;
                worth = std::min(worth, float(history.samples[j]));
            }
            along /= total;
            if (!seen || std::abs(along - expected) > 0.01 * expected + (hi - lo)) continue;
            out.colour.pixels[i] = colour / total;
            out.weight[i] = worth;
        }
    }
    return out;
}

size_t blend_history(Image& shown, const Reprojection& prior, int spp, int end_spp) {
    if (prior.weight.size() != shown.pixels.size()) return 0;
    size_t taken = 0;
    const double n = std::max(0, spp);
    for (size_t i = 0; i < shown.pixels.size(); ++i) {
        const double weight = prior.weight[i];
        if (!(weight > 0)) continue;
        const double end = std::min(end_spp > 0 ? double(end_spp) : std::numeric_limits<double>::infinity(), 4 * weight);
        const double worth = weight * std::max(0.0, 1 - n / end);
        if (!(worth > 0)) continue;
        shown.pixels[i] = (shown.pixels[i] * n + prior.colour.pixels[i] * worth) / (n + worth);
        ++taken;
    }
    return taken;
}

}  // namespace kr::viewer
