#include "render/light.h"

#include <algorithm>
#include <cmath>

#include "core/sampling.h"
#include "render/lanes/vertex.h"

namespace kr {

using vertex::OnePath;

namespace {

double sphere_area(const SphereGeom& s) { return 4.0 * kPi * s.radius * s.radius; }

}  // namespace

bool sample_sphere_light(const SphereGeom& light, const Vec3& p, LightSampling strategy, double u1,
                         double u2, LightSample& out) {
    const Vec3 to_centre = light.centre - p;
    const double d2 = dot(to_centre, to_centre);
    const double r2 = light.radius * light.radius;
    const bool outside = d2 > r2;
    if (strategy == LightSampling::brief_area && outside) {
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
        out.mis_pdf = 0;
        return true;
    }
    if ((strategy == LightSampling::brief || strategy == LightSampling::cone) && outside) {
        const vertex::LightSample<OnePath> sample =
            vertex::sample_sphere_light<OnePath>(strategy, light.centre, light.radius, p, u1, u2, true);
        out = {sample.wi, sample.distance, sample.pdf, sample.mis_pdf};
        return sample.valid;
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
    out.mis_pdf = out.pdf;
    return true;
}

double sphere_light_pdf(const SphereGeom& light, const Vec3& p, const Vec3& wi, double distance,
                        const Vec3& n_light, LightSampling strategy) {
    const vertex::LightHit<vertex::OnePath> hit(strategy, light.centre, light.radius, p, wi, n_light);
    return vertex::sphere_light_pdf<vertex::OnePath>(strategy, hit, light.radius, distance, true);
}

double light_emission_scale(const SphereGeom& light, const Vec3& p, const Vec3& wi, const Vec3& n_light,
                            LightSampling strategy) {
    return vertex::light_emission_scale<vertex::OnePath>(
        strategy, vertex::LightHit<vertex::OnePath>(strategy, light.centre, light.radius, p, wi, n_light));
}

}  // namespace kr
