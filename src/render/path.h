// The steps of path tracing that the one-sample integrator (integrator.cpp) and the
// lane-wise one (lanes/kernels.cpp: eight float or four double lanes) share, so that both trace
// the same paths.
#pragma once

#include "render/material.h"
#include "render/render_scene.h"
#include "render/settings.h"

namespace kr {

// A ray leaving hit point `hit` along `dir`, written field by field into `r`: copying a
// whole Ray just after its fields were stored stalls on store forwarding
// (docs/performance.md, "Design choices and their figures").
// Inline: it runs once per ray, and both tracers call it from their own files.
inline void respawn(Ray& r, const Hit& hit, const Vec3& dir, double tmax = kInfinity, int to_sphere = -1) {
    r.o = hit.p;
    r.d = dir;
    r.tmin = 0;
    r.tmax = tmax;
    r.from_sphere = hit.sphere;
    r.into_from_sphere = dot(dir, hit.n) < 0;
    r.to_sphere = to_sphere;
}

// What a path remembers of its last vertex, for weighing the light it hits next.
struct PathHistory {
    bool full_emission = true;  // camera ray, or the last bounce had no light sample to match
    double last_bsdf_pdf = 0;
    Vec3 last_p;
    int last_sphere = -1;
};

// The weight of emission seen along a path at `hit` (arriving along `incoming`): 1 where no
// light sample could have found it, 0 where the last vertex's light sample counted all of it
// (the brief's own strategy), else the power heuristic against that light sample.
double emission_weight(const RenderScene& scene, LightSampling sampling, const RenderLight& light, const Hit& hit,
                       const Vec3& incoming, const PathHistory& history);

// Next-event estimation: one light, chosen in proportion to its power (point lights cannot be
// hit by chance, so even naive mode samples them). The chosen light's shadow ray, and the
// light it brings over the selection probability if nothing blocks that ray; false: nothing.
bool sample_one_light(const RenderScene& scene, const RenderSettings& settings, const Material& m, const Hit& hit,
                      const SurfacePoint& sp, double u, Vec2 u_point, Ray& shadow, Color& direct);

// Which of a vertex's numbers (Sampler::VertexUse) a path vertex on material `m` reads.
unsigned vertex_numbers_used(const RenderScene& scene, const Material& m, int bounce, int rr_depth);

}  // namespace kr
