#include "render/light.h"

#include "core/sampling.h"

namespace kr {

namespace {

// 1 - cos(theta_max) of the cone a sphere subtends from outside, at squared distance d2.
double cone_one_minus_cos(double r2, double d2) {
    const double sin2_max = r2 / d2;
    const double cos_max = std::sqrt(std::max(0.0, 1.0 - sin2_max));
    return sin2_max / (1.0 + cos_max);  // = 1 - cos_max without cancellation
}

double sphere_area(const SphereGeom& s) { return 4.0 * kPi * s.radius * s.radius; }

}  // namespace

bool sample_sphere_light(const SphereGeom& light, const Vec3& p, LightSampling strategy, double u1,
                         double u2, LightSample& out) {
    const Vec3 to_centre = light.centre - p;
    const double d2 = dot(to_centre, to_centre);
    const double r2 = light.radius * light.radius;
    const bool outside = d2 > r2;
    if (strategy == LightSampling::brief && outside) {
        // Uniform on the hemisphere facing p (density 2/A), cosine about its axis.
        const Vec3 axis = -to_centre / std::sqrt(d2);
        Vec3 n = sample_uniform_sphere(u1, u2);
        if (dot(n, axis) < 0) n = -n;
        const Vec3 w = light.centre + light.radius * n - p;
        const double dist = length(w);
        const double cos_axis = dot(n, axis);
        if (!(dist > 0) || !(cos_axis > 0)) return false;
        out.wi = w / dist;
        out.distance = dist;
        out.pdf = dist * dist / (0.5 * sphere_area(light) * cos_axis);
        return true;
    }
    if (strategy == LightSampling::cone && outside) {
        const double one_minus_cos_max = cone_one_minus_cos(r2, d2);
        const double d = std::sqrt(d2);
        const Vec3 local = sample_uniform_cone(u1, u2, one_minus_cos_max);
        out.wi = Frame::from_normal(to_centre / d).to_world(local);
        // Distance to the near side along wi: d cos - sqrt(r^2 - d^2 sin^2).
        const double sin2 = local.x * local.x + local.y * local.y;
        out.distance = d * local.z - std::sqrt(std::max(0.0, r2 - d2 * sin2));
        out.pdf = uniform_cone_pdf(one_minus_cos_max);
        return out.distance > 0;
    }
    // Uniform over the area; from inside the sphere every point is visible.
    const Vec3 n = sample_uniform_sphere(u1, u2);
    const Vec3 y = light.centre + light.radius * n;
    Vec3 w = y - p;
    const double dist = length(w);
    if (!(dist > 0)) return false;
    w = w / dist;
    const double cos_light = -dot(n, w);  // > 0 when the point faces p from outside
    const double cos_abs = outside ? cos_light : std::abs(cos_light);
    if (!(cos_abs > 0)) return false;
    out.wi = w;
    out.distance = dist;
    out.pdf = dist * dist / (sphere_area(light) * cos_abs);  // area density to solid angle
    return true;
}

double sphere_light_pdf(const SphereGeom& light, const Vec3& p, const Vec3& wi, double distance,
                        const Vec3& n_light, LightSampling strategy) {
    const Vec3 to_centre = light.centre - p;
    const double d2 = dot(to_centre, to_centre);
    const double r2 = light.radius * light.radius;
    const bool outside = d2 > r2;
    if (strategy == LightSampling::brief && outside) return 0;  // never MIS-weighted
    if (strategy == LightSampling::cone && outside) return uniform_cone_pdf(cone_one_minus_cos(r2, d2));
    const double cos_abs = std::abs(dot(n_light, wi));
    if (!(cos_abs > 0)) return 0;
    return distance * distance / (sphere_area(light) * cos_abs);
}

}  // namespace kr
