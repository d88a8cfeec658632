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

}  // namespace kr
