#include "render/material.h"

#include "core/sampling.h"

namespace kr {

Color eval_smooth(const Material& m, const SurfacePoint& sp, const Vec3& wo) {
    if (m.type != MaterialType::diffuse) return {};
    const double cos_o = dot(sp.ns(), wo);
    return cos_o > 0 ? m.rho * (kInvPi * cos_o) : Color();  // Lambert: rho / pi
}

double pdf_smooth(const Material& m, const SurfacePoint& sp, const Vec3& wo) {
    if (m.type != MaterialType::diffuse) return 0;
    return cosine_hemisphere_pdf(dot(sp.ns(), wo));
}

DielectricSplit split_dielectric(const Material& m, const SurfacePoint& sp, const Vec3& wi) {
    const Vec3 ns = sp.ns();
    // eta is inside / outside; entering from outside the ratio incident/transmitted is 1/eta.
    const double eta_ratio = sp.front ? 1.0 / m.eta : m.eta;
    DielectricSplit split;
    split.reflected = reflect(wi, ns);
    split.reflectance = fresnel_dielectric(-dot(wi, ns), eta_ratio);
    if (split.reflectance < 1.0 && !refract(wi, ns, eta_ratio, split.transmitted))
        split.reflectance = 1.0;  // grazing rounding: treat as total internal reflection
    return split;
}

bool sample_material(const Material& m, const SurfacePoint& sp, const Vec3& wi, double u_lobe,
                     Vec2 u, ScatterSample& out) {
    const Vec3 ns = sp.ns();
    out.transmitted = false;
    switch (m.type) {
        case MaterialType::diffuse: {
            const Vec3 local = sample_cosine_hemisphere(u.x, u.y);
            out.direction = Frame::from_normal(ns).to_world(local);
            out.pdf = cosine_hemisphere_pdf(local.z);
            out.weight = m.rho;  // (rho/pi) cos / (cos/pi)
            out.smooth = true;
            return out.pdf > 0;
        }
        case MaterialType::specular:
            out.direction = reflect(wi, ns);
            out.weight = m.rho;
            out.smooth = false;
            return true;
        case MaterialType::glossy: {
            // Brief eq. 2: the mirror direction perturbed by roughness; weight rho, as the
            // lobe is sampled exactly by its own distribution.
            out.direction = perturb_direction(reflect(wi, ns), m.roughness, u.x, u.y);
            out.weight = m.rho;
            out.smooth = false;
            return dot(out.direction, ns) > 0;
        }
        case MaterialType::dielectric:
        case MaterialType::translucent: {
            const DielectricSplit split = split_dielectric(m, sp, wi);
            // Choose reflection with probability F: weights F rhoR / F and (1-F) rhoT / (1-F).
            const bool reflect_branch = u_lobe < split.reflectance;
            const double beta = m.type == MaterialType::translucent ? m.roughness : 0.0;
            out.smooth = false;
            if (reflect_branch) {
                out.direction = perturb_direction(split.reflected, beta, u.x, u.y);
                out.weight = m.rho_r;
                return dot(out.direction, ns) > 0;
            }
            out.direction = perturb_direction(split.transmitted, beta, u.x, u.y);
            out.weight = m.rho_t;
            out.transmitted = true;
            return dot(out.direction, ns) < 0;
        }
    }
    return false;
}

}  // namespace kr
