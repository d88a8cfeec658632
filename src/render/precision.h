#pragma once
// Whether single-precision lanes resolve what a scene's rays must: the gaps between surfaces,
// and between lights and the surfaces around them. float_lanes_fit (trace.h) asks this beside
// its range checks; prepare_scene and build_accel store the answer in the RenderScene, since
// it looks at pairs of spheres (docs/robustness.md, "Surfaces closer than float rounding").
//
// Two tolerances of the float lanes decide it (measured in docs/robustness.md):
// - a hit point is off by a few float epsilons of the magnitudes its root is computed from
//   (|centre|_1 + radius of the two spheres): a surface nearer another than kFloatHitUlps of
//   those magnitudes may be crossed on the wrong side (a glass shell around a glass ball);
// - a shadow segment ends kSegmentEndTolerance (64 float epsilons) of tmax + |origin|_1 +
//   |blocker centre|_1 short of its light: a surface nearer a light than that is not seen
//   to block it (a lamp inside a lampshade 1e-5 larger lights the room).
// Spheres that touch or cross have such a near zone only around where they meet; it is
// allowed while it covers at most kFloatNearFraction of either sphere's area (the brief's
// scenes and the examples: at most 1/85, a small lamp beside a ball of denoise_many_lights). Where a shell is near all over, or a point light sits within the
// end tolerance of a surface (but not on it, as double precision sees it), the scene takes
// the double lanes.
#include "render/render_scene.h"

namespace kr {

inline constexpr double kFloatHitUlps = 16;             // float epsilons of the magnitudes
// the lanes' kSegmentEndTolerance (64), and 4 for the rounding of the crossing it cuts
inline constexpr double kFloatShadowEndUlps = 68;
inline constexpr double kFloatNearFraction = 1.0 / 32;  // of a sphere's area

// The fraction of sphere A's area that lies within `tolerance` of sphere B's surface (points
// p of A with | |p - centre_b| - radius_b | <= tolerance). Exact: |p - centre_b|^2 is linear
// in the cosine about the axis of the centres, and area is uniform in that cosine.
double near_surface_fraction(const SphereGeom& a, const SphereGeom& b, double tolerance);

// The gap rules above, for the scene's spheres and lights (the camera plays no part).
bool float_resolves_gaps(const RenderScene& scene);

// The size rule of float_lanes_fit (trace.h): a float sphere test rounds to about 2^-24 of
// the distances it meets (the coordinates of its ray's origin and of the sphere's centre, and
// the distance between them), and that must stay below 2^-12 of the sphere's radius, as
// kFloatSizeRatio says. Where every distance in the scene (the camera's, its lens's and every
// sphere's from the origin) is within kFloatSizeRatio smallest radii, it holds at once.
// Otherwise it is checked sphere by sphere over the points rays can reach
// (float_reach_fits): a large floor's far side counts only where a ray can get there.
inline constexpr double kFloatSizeRatio = 0x1.0p12;
bool float_sizes_fit(const RenderScene& scene);

// The per-sphere check. Rays start at the lens and on surfaces they hit. A ray that hits an
// opaque sphere from outside starts within the tangent length sqrt(d^2 - r^2) of its origin
// (d: the origin's distance from the centre), and a ray leaving a sphere's surface outwards
// never hits that sphere again (spheres are convex). So the part of each sphere rays can
// reach lies in its box and within that tangent length of the box of the points rays start
// from elsewhere (the lens, point lights and the other spheres' reach), worked out until no
// box grows. A sphere rays may enter (a dielectric, the lens inside it) or that lights are
// sampled on (an emitter) counts whole. Then each sphere's radius must be at least
// 1/kFloatSizeRatio of: the farthest reach of any point from the origin, its own farthest
// point from the origin, and the farthest reach of any point from its centre.
bool float_reach_fits(const RenderScene& scene);

}  // namespace kr
