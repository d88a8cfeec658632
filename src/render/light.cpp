#include "render/light.h"

#include <algorithm>
#include <cmath>

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


// Where the brief strategy puts its points: on the hemisphere of the light facing p, at
// u = cos_axis and a uniform azimuth. The brief's integrand has cos_axis / dist^2 with
// dist^2 = s = a - b u (a = d^2 + r^2, b = 2 d r): density proportional to u for a far light
// (s nearly constant), to 1/s close to it. A mixture of the two, both sampled in closed form:
// u = sqrt(xi) with weight alpha, log-uniform s with weight 1 - alpha, alpha = 1 / (1 + v^3)
// where v = ln(a / (d - r)^2) grows as p nears the light. Each part keeps the other's weight
// bounded: near, the log-uniform part; far, the u part.
struct BriefProposal {
    // ln(a / (d - r)^2) = -ln(1 - b / a): one log of a ratio, cheaper than log1p. For a far
    // light the ratio is near 1 and loses relative precision, but v_max is then tiny and the
    // log-uniform part's weight 1 - alpha ~ v_max^3 negligible.
    // log_positive: packet.cpp takes the same logarithm lane-wise.
    static double log_ratio(double a, double gap) { return log_positive(a / (gap * gap)); }

    // mix = 1 / alpha = 1 + v_max^3, so that sampling needs no division.
    double a, b, v_max, mix, alpha;
    BriefProposal(const SphereGeom& light, double d)
        : a(d * d + light.radius * light.radius),
          b(2 * d * light.radius),
          v_max(log_ratio(a, d - light.radius)),
          mix(1.0 + v_max * v_max * v_max),
          alpha(1.0 / mix) {}
    // Density of u on [0, 1] times s = a - b u: alpha 2u s + (1 - alpha) b / v_max. The
    // callers want it times the squared distance, which is s, so s cancels its division.
    double pdf_times_s(double u, double s) const { return alpha * (2 * u * s + v_max * v_max * b); }
    double pdf(double u) const { const double s = a - b * u; return pdf_times_s(u, s) / s; }
    double sample(double xi) const {
        const double x = xi * mix;  // below 1: the u part, with xi / alpha = x
        if (x < 1) return std::sqrt(x);
        // s = a exp(-t v_max), t uniform: log-uniform on [(d - r)^2, a]; u = (a - s) / b.
        const double t = (x - 1) / (v_max * v_max * v_max);
        return std::clamp(-a * std::expm1(-t * v_max) / b, 0.0, 1.0);
    }
};
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
    if (strategy == LightSampling::brief && outside) {
        // The brief's integral over the hemisphere facing p, with the light-side cosine about
        // that hemisphere's axis: E = int f L cos_i cos_axis / dist^2 dA(y). The brief draws y
        // uniformly on the hemisphere, whose weight A cos_axis / (2 dist^2) explodes for
        // shading points close to the light; here y comes from BriefProposal, close to
        // cos_axis / dist^2 near and far, so the weight stays bounded.
        const double d = std::sqrt(d2);
        const BriefProposal proposal(light, d);
        const double cos_axis = proposal.sample(u1);
        const double sin_axis = std::sqrt(std::max(0.0, 1.0 - cos_axis * cos_axis));
        double sin_phi, cos_phi;
        sin_cos_turns(u2, sin_phi, cos_phi);
        const Vec3 axis = -to_centre / d;
        const Vec3 n = Frame::from_normal(axis).to_world({sin_axis * cos_phi, sin_axis * sin_phi, cos_axis});
        const Vec3 w = light.centre + light.radius * n - p;
        const double dist2 = dot(w, w);
        const double dist = std::sqrt(dist2);
        if (!(dist > 0) || !(cos_axis > 0)) return false;
        out.wi = w / dist;
        out.distance = dist;
        // Area density on the sphere is the density of u over 2 pi r^2 (dA = r^2 du dphi);
        // times dist^2 it converts to solid angle.
        const double area_density_dist2 = proposal.pdf_times_s(cos_axis, dist2) / (2 * kPi * r2);
        out.pdf = area_density_dist2 / cos_axis;  // f L cos_axis / dist^2 / area_density
        // BSDF sampling reaches the visible cap only, so only there are the two combined;
        // the band behind the silhouette keeps this strategy's full weight (mis_pdf 0).
        const double cos_light = -dot(n, out.wi);
        const bool visible_cap = cos_axis * d > light.radius && cos_light > 0;
        out.mis_pdf = visible_cap ? area_density_dist2 / cos_light : 0.0;
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
        out.mis_pdf = out.pdf;
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
    out.mis_pdf = out.pdf;
    return true;
}

double sphere_light_pdf(const SphereGeom& light, const Vec3& p, const Vec3& wi, double distance,
                        const Vec3& n_light, LightSampling strategy) {
    const Vec3 to_centre = light.centre - p;
    const double d2 = dot(to_centre, to_centre);
    const double r2 = light.radius * light.radius;
    const bool outside = d2 > r2;
    const double cos_abs = std::abs(dot(n_light, wi));
    if (strategy == LightSampling::brief_area && outside) return 0;  // never combined
    if (strategy == LightSampling::brief && outside) {
        // Solid-angle density of the brief strategy's point at the (visible) hit.
        const double cos_axis = -dot(n_light, to_centre) / std::sqrt(d2);
        if (!(cos_abs > 0) || !(cos_axis > 0)) return 0;
        const double area_density = BriefProposal(light, std::sqrt(d2)).pdf(cos_axis) / (2 * kPi * r2);
        return area_density * distance * distance / cos_abs;
    }
    if (strategy == LightSampling::cone && outside) return uniform_cone_pdf(cone_one_minus_cos(r2, d2));
    if (!(cos_abs > 0)) return 0;
    return distance * distance / (sphere_area(light) * cos_abs);
}

double light_emission_scale(const SphereGeom& light, const Vec3& p, const Vec3& wi, const Vec3& n_light,
                            LightSampling strategy) {
    const Vec3 from_centre = p - light.centre;
    const double d2 = dot(from_centre, from_centre);
    if (!is_brief(strategy) || !(d2 > light.radius * light.radius)) return 1.0;
    // The brief's integrand over the light's area has cos_axis where the exact one has the
    // light-side cosine: in solid angle, L cos_axis / cos_light instead of L.
    const double cos_axis = dot(n_light, from_centre) / std::sqrt(d2);
    const double cos_light = std::abs(dot(n_light, wi));
    return cos_light > 0 && cos_axis > 0 ? cos_axis / cos_light : 0.0;
}

}  // namespace kr
