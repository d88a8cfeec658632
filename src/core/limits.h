// The ranges of the numbers users give keithray: scene files (the loader), the flags of
// render, view and bench, and the size of what is read. One place, so that the loader, the
// command lines and the docs agree (docs/cli.md, "Limits").
#pragma once

#include <cstdint>

namespace kr {

inline constexpr int kMaxDepth = 20;              // scattering events per path (SPEC: never above 20)
inline constexpr int kMaxDimension = 32768;       // pixels per side of an image
inline constexpr int kMaxSamples = 1 << 24;       // samples per pixel: "samples", --spp
inline constexpr int kMaxThreads = 4096;          // --threads
inline constexpr int kMaxBlur = 4096;             // --blur radius in pixels
inline constexpr long long kMaxSeed = 1ll << 62;  // --seed
// --time: up to about 11.6 days of rendering.
inline constexpr double kMaxSeconds = 1e6;
// --noise: relative RMS error targets. Error falls as 1/sqrt(passes), so 1e-4 already
// needs about 10^8 passes where one pass gives an error of 1.
inline constexpr double kMinNoise = 1e-4, kMaxNoise = 1;
// Passes of --time or --noise without --spp: the error after 65536 passes is 1/256 of a
// one-pass image's, and a noise target the scene cannot reach still ends.
inline constexpr int kMaxOpenEndedPasses = 1 << 16;
// A scene file: checked by size for regular files, by a bounded read for others
// (/dev/zero, a FIFO). The largest test scene, 100,000 spheres, is 21.5 MB.
inline constexpr uint64_t kMaxSceneFileBytes = uint64_t(64) << 20;

}  // namespace kr
