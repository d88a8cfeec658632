// Checkpoints: a render's state in a file, to resume it later (`keithray render --checkpoint
// FILE`, `--resume FILE`). A resumed render is byte for byte the uninterrupted one: the state
// holds every sum, count, sample index, the adaptive mask and the allocation's carried
// fractions, and ProgressiveDriver counts passes from state.passes and repeats a noise check
// the state ends on.
//
// Format (version 2, little-endian, as x86-64 and AArch64 lay it out in memory):
//   "keithray checkpoint\n"  magic
//   u32 version, u64 scene fingerprint, u32 key length, key text ("integrator=pt seed=0 ..."),
//   i32 width, i32 height, i32 passes, u64 rays, u64 non-finite samples,
//   per pixel: radiance_sum (3 f64), radiance_compensation (3 f64), depth_sum (f64), luminance_sq_sum (f64),
//   radiance_sq_sum (3 f64), sample_count (u32), sample_index (u32),
//   u8 + per pixel u8: the adaptive mask (when the u8 is 1), u8 + per pixel f32: the carried
//   fractions (when the u8 is 1), and last a u64 FNV-1a of every byte before it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "render/progressive.h"
#include "scene/scene.h"

namespace kr {

inline constexpr uint32_t kCheckpointVersion = 3;

// What a checkpoint must match to be resumed: the scene (a fingerprint of its canonical JSON
// without the output path and display block, which do not change the samples), the settings
// and stop rule that shape the samples, the pass limit included (an open-ended render's
// implicit cap too, so one resumed without its --time or --noise is refused rather than
// ending elsewhere), as "name=value" words so that a refusal names the one that differs,
// and the image size. The time limit is not in it: more time goes on to the same samples.
struct CheckpointKey {
    uint64_t scene = 0;
    std::string settings;
    int width = 0, height = 0;
};
CheckpointKey checkpoint_key(const Scene& scene, const RenderScene& prepared, const RenderSettings& settings,
                             const StopRule& rule);

// Reads checkpoint `file`, refusing one larger than a checkpoint of `expected` can be.
// Throws std::runtime_error (one line naming the file).
std::string read_checkpoint_file(const std::filesystem::path& file, const CheckpointKey& expected);

std::string encode_checkpoint(const CheckpointKey& key, const RenderState& state);

// Restores `state` from a checkpoint's bytes, or throws std::runtime_error with one line
// "<file>: <what differs or is wrong>" (another scene, settings or size, another version, a
// truncated or damaged file); `state` is then untouched.
void decode_checkpoint(const std::string& bytes, const std::filesystem::path& file, const CheckpointKey& expected,
                       RenderState& state);

}  // namespace kr
