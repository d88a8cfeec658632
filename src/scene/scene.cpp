#include "scene/scene.h"

#include <cmath>

namespace kr {

// The file stores the output relative to itself so scenes can move with their outputs;
// a scene built in code (no source file) resolves against the current directory.
std::filesystem::path Scene::output_path() const {
    const std::filesystem::path output(renderer.output);
    if (source_file.empty()) return output.lexically_normal();
    return (source_file.parent_path() / output).lexically_normal();
}

namespace {

constexpr MaterialParam colour_param(std::string_view name, Color Material::*member) {
    MaterialParam p;
    p.name = name;
    p.colour = member;
    return p;
}

constexpr MaterialParam number_param(std::string_view name, double Material::*member, std::string_view expected,
                                     double lo, double hi, bool lo_open, bool hi_open, double edit_lo,
                                     double edit_hi, float edit_speed) {
    MaterialParam p;
    p.name = name;
    p.number = member;
    p.expected = expected;
    p.lo = lo, p.hi = hi, p.lo_open = lo_open, p.hi_open = hi_open;
    p.edit_lo = edit_lo, p.edit_hi = edit_hi, p.edit_speed = edit_speed;
    return p;
}

const MaterialParam kRho = colour_param("rho", &Material::rho);
const MaterialParam kRhoR = colour_param("rhoR", &Material::rho_r);
const MaterialParam kRhoT = colour_param("rhoT", &Material::rho_t);
const MaterialParam kRoughness =
    number_param("roughness", &Material::roughness, "a roughness in [0, 1)", 0, 1, false, true, 0, 0.999, 0.002f);
const MaterialParam kEta = number_param("eta", &Material::eta, "a refractive index eta > 0", 0, HUGE_VAL, true, false,
                                        1.0 / 4, 4, 0.002f);

const MaterialParam kRhoOnly[] = {kRho};
const MaterialParam kGlossy[] = {kRho, kRoughness};
const MaterialParam kDielectric[] = {kRhoR, kRhoT, kEta};
const MaterialParam kTranslucent[] = {kRhoR, kRhoT, kEta, kRoughness};

}  // namespace

std::span<const MaterialParam> material_params(MaterialType type) {
    switch (type) {
        case MaterialType::diffuse:
        case MaterialType::specular: return kRhoOnly;
        case MaterialType::glossy: return kGlossy;
        case MaterialType::dielectric: return kDielectric;
        case MaterialType::translucent: return kTranslucent;
    }
    return {};
}

}  // namespace kr
