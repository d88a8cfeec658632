#include "render/render_scene.h"

#include "render/precision.h"

#include <array>
#include <map>
#include <stdexcept>

#include "core/text.h"
#include "render/lanes/vertex.h"
#include "scene/load.h"

namespace kr {

bool sphere_roots(const SphereGeom& s, const Vec3& o, const Vec3& d, double& t_near, double& t_far) {
    const Vec3 f = o - s.centre;
    const double b = dot(f, d);  // half the usual b, since |d| = 1
    // Discriminant as r^2 - |f - b d|^2: the distance of the line from the centre, computed
    // without subtracting two large, nearly equal squares.
    const Vec3 perp = f - b * d;
    const double r2 = s.radius * s.radius;
    const double disc = r2 - dot(perp, perp);
    if (disc < 0) return false;
    const double c = dot(f, f) - r2;
    // Vieta: the root of larger magnitude from q, the other from c / q (no cancellation).
    const double q = -b - std::copysign(std::sqrt(disc), b);
    if (q == 0) {  // origin at the centre of a zero-size sphere, or tangent at the origin
        t_near = t_far = 0;
        return true;
    }
    const double t0 = c / q, t1 = q;
    t_near = std::min(t0, t1);
    t_far = std::max(t0, t1);
    return true;
}

double segment_end_tolerance(const Vec3& f, double tmax) {
    return kSegmentEndTolerance * (std::abs(f.x) + std::abs(f.y) + std::abs(f.z) + tmax);
}

double accepted_root(const SphereGeom& s, int index, const Ray& ray, bool shadow) {
    if (index == ray.to_sphere) return kInfinity;
    const bool is_origin = index == ray.from_sphere;
    if (is_origin && !ray.into_from_sphere) return kInfinity;
    double t_near, t_far;
    if (!sphere_roots(s, ray.o, ray.d, t_near, t_far)) return kInfinity;
    // A root at the origin (t = 0) is the surface a ray starts on, such as a camera placed
    // exactly on a sphere.
    const double tmax = shadow && ray.tmax < kInfinity ? ray.tmax - segment_end_tolerance(ray.o - s.centre, ray.tmax)
                                                       : ray.tmax;
    if (!is_origin && t_near >= ray.tmin && t_near > 0 && t_near <= tmax) return t_near;
    if (t_far >= ray.tmin && t_far > 0 && t_far <= tmax) return t_far;
    return kInfinity;
}

// Fills `hit` for sphere `index` at distance `t` along the ray.
static void fill_hit(const RenderScene& scene, const Ray& ray, int best_sphere, double best, Hit& hit) {
    const SphereGeom& s = scene.spheres[best_sphere];
    hit.t = best;
    hit.sphere = best_sphere;
    // Project the hit point back onto the sphere so the next ray starts on its surface.
    const Vec3 offset = ray.o + best * ray.d - s.centre;
    const double offset_length = length(offset);
    hit.n = offset_length > 0 ? offset / offset_length : -ray.d;
    hit.p = s.centre + hit.n * s.radius;
}

bool RenderScene::intersects(const Ray& ray, Hit& hit) const {
    if (linear_scan) return intersects_linear(ray, hit);
    double t;
    const int sphere = bvh.closest(ray, t);
    if (sphere < 0) return false;
    fill_hit(*this, ray, sphere, t, hit);
    return true;
}

bool RenderScene::hit_on(const Ray& ray, int sphere, Hit& hit) const {
    const double t = accepted_root(spheres[size_t(sphere)], sphere, ray, false);
    if (!(t < kInfinity)) return false;
    fill_hit(*this, ray, sphere, t, hit);
    return true;
}

bool RenderScene::is_occluded(const Ray& ray) const { return linear_scan ? is_occluded_linear(ray) : bvh.any(ray); }

bool RenderScene::intersects_linear(const Ray& ray, Hit& hit) const {
    double best = kInfinity;
    int best_sphere = -1;
    for (int i = 0; i < static_cast<int>(spheres.size()); ++i) {
        const double t = accepted_root(spheres[size_t(i)], i, ray, false);
        if (t < best) {
            best = t;
            best_sphere = i;
        }
    }
    if (best_sphere < 0) return false;
    fill_hit(*this, ray, best_sphere, best, hit);
    return true;
}

bool RenderScene::is_occluded_linear(const Ray& ray) const {
    for (int i = 0; i < static_cast<int>(spheres.size()); ++i)
        if (accepted_root(spheres[size_t(i)], i, ray, true) < kInfinity) return true;
    return false;
}

namespace {

// Whether two render scenes' lights are where the gap check (precision.h) looks: the same
// lights at the same places (position, sphere), each emitting or not as before.
bool same_light_geometry(const RenderScene& a, const RenderScene& b) {
    const auto emits = [](const Color& c) { return c != Color(); };
    if (a.lights.size() != b.lights.size()) return false;
    for (size_t i = 0; i < a.lights.size(); ++i) {
        const RenderLight &x = a.lights[i], &y = b.lights[i];
        if (x.type != y.type || x.position != y.position || x.sphere != y.sphere || emits(x.power) != emits(y.power))
            return false;
    }
    return a.sphere_light == b.sphere_light;
}

// The natural log of a light's emitted power's luminance (lights are chosen in proportion to
// it): 4 pi I for a point light, pi A Le for a sphere emitting from its outside. As a
// logarithm: a file may hold an intensity of 1e308 or a radius of 1e200, whose power
// overflows a double (and inf / inf would make every share NaN).
double log_light_power(const RenderScene& rs, const RenderLight& light) {
    const double scale = max_component(light.power);  // luminance(power / scale) is in (0.07, 1]
    const double log_luminance = scale > 0 ? std::log(scale) + std::log(luminance(light.power / scale)) : -kInfinity;
    switch (light.type) {
    case LightType::point: return std::log(4.0 * kPi) + log_luminance;
    case LightType::area: return std::log(4.0 * kPi * kPi) + 2.0 * std::log(rs.spheres[light.sphere].radius) + log_luminance;
    }
    return -kInfinity;
}

}  // namespace

bool same_world(const RenderScene& a, const RenderScene& b) {
    auto same_material = [](const Material& x, const Material& y) {
        return x.type == y.type && x.rho == y.rho && x.rho_r == y.rho_r && x.rho_t == y.rho_t && x.eta == y.eta &&
               x.roughness == y.roughness;
    };
    if (a.spheres != b.spheres || a.sphere_light != b.sphere_light || a.sphere_material.size() != b.sphere_material.size())
        return false;
    for (size_t i = 0; i < a.sphere_material.size(); ++i)
        if (!same_material(a.materials[size_t(a.sphere_material[i])], b.materials[size_t(b.sphere_material[i])]))
            return false;
    if (a.lights.size() != b.lights.size()) return false;
    for (size_t i = 0; i < a.lights.size(); ++i) {
        const RenderLight &x = a.lights[i], &y = b.lights[i];
        if (x.type != y.type || !(x.position == y.position) || x.sphere != y.sphere || !(x.power == y.power))
            return false;
    }
    const RendererSettings &ra = a.renderer, &rb = b.renderer;
    return ra.type == rb.type && ra.width == rb.width && ra.height == rb.height && ra.depth == rb.depth;
}

bool renders_same(const RenderScene& a, const RenderScene& b) {
    if (!same_world(a, b)) return false;
    const CameraModel &ca = a.camera, &cb = b.camera;
    // A closed lens (radius 0) is a pinhole: the focal distance draws nothing (camera.cpp).
    const bool lens = ca.lens_radius > 0 || cb.lens_radius > 0;
    if (!(ca.position == cb.position) || !(ca.forward == cb.forward) || !(ca.right == cb.right) || !(ca.up == cb.up) ||
        ca.tan_half_fov != cb.tan_half_fov || ca.aspect != cb.aspect || ca.lens_radius != cb.lens_radius ||
        (lens && ca.focal_distance != cb.focal_distance))
        return false;
    return a.renderer.samples == b.renderer.samples && a.accel_backend == b.accel_backend && a.linear_scan == b.linear_scan;
}

RenderScene prepare_scene(const Scene& scene, std::vector<std::string>* warnings, const RenderScene* previous) {
    const std::string file = scene.source_file.string();
    auto warn = [&](const std::string& path, const std::string& message) {
        if (warnings) warnings->push_back(show_user_text(file) + ": " + path + ": " + message);
    };
    RenderScene rs;
    rs.renderer = scene.renderer;
    if (scene.camera < 0 || scene.camera >= static_cast<int>(scene.cameras.size()))
        throw SceneError(file, "/scene/camera", "no active camera");
    try {
        rs.camera = CameraModel::from(scene.cameras[scene.camera]);
    } catch (const std::invalid_argument& e) {
        throw SceneError(file, "/cameras/" + std::to_string(scene.camera), e.what());
    }

    // Materials are copied on first use, so the render scene holds only referenced ones.
    std::vector<int> material_slot(scene.materials.size(), -1);
    auto use_material = [&](int m) {
        if (material_slot[m] < 0) {
            material_slot[m] = static_cast<int>(rs.materials.size());
            rs.materials.push_back(scene.materials[m]);
        }
        return material_slot[m];
    };

    std::vector<bool> active(scene.lights.size(), false);
    std::vector<RenderLight> on_spheres;  // the lights the primitives carry, by sphere
    for (int l : scene.active_lights) active[size_t(l)] = true;

    // One sphere per distinct shape: a repeated primitive would only hit itself again. The
    // same holds for two shapes of exactly the same centre and radius (a copy under another
    // id): coincident surfaces would shadow each other at random, so the first primitive
    // renders the sphere and a later one is left out, with a warning naming both.
    std::vector<int> shape_sphere(scene.shapes.size(), -1);
    std::map<std::array<double, 4>, int> geometry_sphere;  // exact centre and radius -> sphere
    std::vector<size_t> sphere_primitive;                  // per sphere: the primitive it renders
    for (size_t i = 0; i < scene.primitives.size(); ++i) {
        const Primitive& prim = scene.primitives[i];
        const std::string path = "/scene/primitives/" + std::to_string(i);
        const Shape& shape = scene.shapes[prim.shape];
        if (shape_sphere[prim.shape] < 0) {
            const auto [found, fresh] = geometry_sphere.try_emplace(
                {shape.centre.x, shape.centre.y, shape.centre.z, shape.radius}, static_cast<int>(rs.spheres.size()));
            if (!fresh) shape_sphere[prim.shape] = found->second;
        }
        if (shape_sphere[prim.shape] >= 0) {
            const int existing = shape_sphere[prim.shape];
            const Primitive& first = scene.primitives[sphere_primitive[size_t(existing)]];
            const bool same_material = rs.materials[rs.sphere_material[existing]].id == scene.materials[prim.material].id;
            const bool emits = prim.type == PrimitiveType::emissive && active[size_t(prim.light)];
            const bool same_light = emits == (rs.sphere_light[existing] >= 0) && (!emits || prim.light == first.light);
            if (first.shape == prim.shape) {
                if (!same_material || !same_light)
                    warn(path, "shape " + in_quotes(shape.id) + " is already used by an earlier primitive; this one is ignored");
                continue;
            }
            std::string message = "primitive " + in_quotes(prim.id) + " (shape " + in_quotes(shape.id) +
                                  ") is the same sphere as primitive " + in_quotes(first.id) + " (shape " +
                                  in_quotes(scene.shapes[first.shape].id) + "); rendered once, as the first";
            if (!same_material) message += "; its material " + in_quotes(scene.materials[prim.material].id) + " is left out";
            if (!same_light)
                message += emits
                               ? "; its light " + in_quotes(scene.lights[prim.light].id) + " does not emit"
                               : "; the first one's light emits";
            warn(path, message);
            continue;
        }
        shape_sphere[prim.shape] = static_cast<int>(rs.spheres.size());
        sphere_primitive.push_back(i);
        rs.spheres.push_back({shape.centre, shape.radius});
        rs.sphere_material.push_back(use_material(prim.material));
        int light_index = -1;
        // An emissive primitive whose light is not in /scene/lights is switched off: its
        // sphere stays, with its material, and emits nothing (the viewer's light checkbox).
        if (prim.type == PrimitiveType::emissive && active[size_t(prim.light)]) {
            const Light& light = scene.lights[prim.light];
            light_index = static_cast<int>(on_spheres.size());
            on_spheres.push_back({light.type, light.power, {}, static_cast<int>(rs.spheres.size()) - 1, 0});
            if (light.shape != prim.shape)
                warn(path + "/shape", "differs from the shape of light " + quote_user_text(light.id) +
                                          "; the primitive's shape emits");
        }
        rs.sphere_light.push_back(light_index);
    }

    // Which lights some emissive primitive carries (one pass, not one per light: a file may
    // have 10^5 of each).
    std::vector<bool> carried(scene.lights.size(), false);
    for (const Primitive& prim : scene.primitives)
        if (prim.type == PrimitiveType::emissive && prim.light >= 0) carried[size_t(prim.light)] = true;
    for (size_t k = 0; k < scene.active_lights.size(); ++k) {
        const Light& light = scene.lights[scene.active_lights[k]];
        if (!vertex::light_kind(light.type).on_sphere) {
            rs.lights.push_back({light.type, light.power, light.position, -1, 0});
            continue;
        }
        if (!carried[size_t(scene.active_lights[k])])
            throw SceneError(file, "/scene/lights/" + std::to_string(k),
                             std::string(light_type_names.name(light.type)) + " light " + quote_user_text(light.id) +
                                 " is not carried by any emissive primitive; add one with \"light\": " +
                                 quote_user_text(light.id));
    }
    // The lights on the spheres after those off them; sphere_light indexes the whole array.
    rs.lights_off_spheres = rs.lights.size();
    rs.lights.insert(rs.lights.end(), on_spheres.begin(), on_spheres.end());
    for (int& light : rs.sphere_light)
        if (light >= 0) light += int(rs.lights_off_spheres);

    // Light selection probabilities proportional to emitted power (luminance).
    std::vector<double> log_power;
    for (const RenderLight& light : rs.lights) log_power.push_back(log_light_power(rs, light));
    const size_t n = log_power.size();
    double log_max = -kInfinity, total = 0;
    for (double p : log_power) log_max = std::max(log_max, p);
    std::vector<double> power(n, 0.0);  // relative to the brightest light
    if (log_max > -kInfinity)
        for (size_t i = 0; i < n; ++i) total += power[i] = std::exp(log_power[i] - log_max);
    for (size_t i = 0; i < n; ++i)  // equal shares when every light is black (keeps pdfs defined)
        rs.lights[i].select_prob = total > 0 ? power[i] / total : 1.0 / double(n);
    // The BVH depends on the spheres alone, and at many spheres its build is most of the
    // viewer's latency after a camera edit; the gap check depends on the spheres and the
    // lights (docs/performance.md, "Design choices and their figures").
    if (previous && previous->accel_backend == rs.accel_backend && previous->spheres == rs.spheres) {
        rs.bvh = previous->bvh;
        rs.float_gaps_resolved = same_light_geometry(*previous, rs) ? previous->float_gaps_resolved
                                                                    : rs.bvh.lanes_cast() && float_resolves_gaps(rs);
    } else {
        rs.build_accel();
    }
    return rs;
}

void RenderScene::build_accel() {
    bvh.build(spheres, accel_backend);
    float_gaps_resolved = bvh.lanes_cast() && float_resolves_gaps(*this);
}

}  // namespace kr
