#include "render/material.h"

#include "render/lanes/vertex.h"

namespace kr {

using vertex::OneMaterial;
using vertex::OnePath;

Color eval_smooth(const Material& m, const SurfacePoint& sp, const Vec3& wo) {
    if (!has_smooth_lobe(m)) return {};
    return vertex::eval_smooth_lobe<OnePath>(OneMaterial{m}, sp.ns(), wo).f_cos;
}

DielectricSplit split_dielectric(const Material& m, const SurfacePoint& sp, const Vec3& wi) {
    const Vec3 ns = sp.ns();
    const double wi_n = dot(wi, ns);
    const vertex::FresnelSplit<OnePath> fresnel = vertex::split_dielectric<OnePath>(m.eta, sp.front, wi, ns, wi_n);
    DielectricSplit split;
    split.reflected = wi - ns * (2.0 * wi_n);  // reflect
    split.reflectance = fresnel.reflectance;
    split.transmitted = fresnel.transmitted;
    return split;
}

bool sample_material(const Material& m, const SurfacePoint& sp, const Vec3& wi, double u_lobe, Vec2 u,
                     ScatterSample& out) {
    const vertex::Scatter<OnePath> s =
        vertex::sample_material<OnePath>(OneMaterial{m}, true, wi, sp.ns(), sp.front, u_lobe, u.x, u.y);
    out.direction = s.direction;
    out.weight = s.weight;
    out.pdf = s.pdf;
    out.smooth = s.smooth;
    out.transmitted = s.transmitted;
    return s.ok;
}

}  // namespace kr
