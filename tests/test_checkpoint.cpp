// Checkpoints (render/checkpoint.h): a render stopped after k passes and resumed from its
// checkpoint is bit for bit the uninterrupted one; a checkpoint of another scene, other
// settings or another size, or a damaged one, is refused with one line naming the file and
// what differs. And on the command line: SIGINT writes the checkpoint and no image, and
// --resume finishes the same bytes.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "core/hash.h"
#include "render/checkpoint.h"
#include "scene/save.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

void expect_same_state(const RenderState& a, const RenderState& b) {
    EXPECT_EQ(a.passes, b.passes);
    EXPECT_EQ(a.rays, b.rays);
    EXPECT_EQ(a.sample_count(), b.sample_count());
    EXPECT_EQ(a.sample_index(), b.sample_index());
    EXPECT_EQ(a.plan.active, b.plan.active);
    EXPECT_EQ(a.depth_sum(), b.depth_sum());
    EXPECT_EQ(a.radiance_compensation().size(), b.radiance_compensation().size());
    for (size_t i = 0; i < a.radiance_compensation().size(); ++i)
        EXPECT_EQ(a.radiance_compensation()[i].x, b.radiance_compensation()[i].x) << i;
    EXPECT_EQ(a.luminance_sq_sum(), b.luminance_sq_sum());
    size_t differ = 0;
    for (size_t i = 0; i < a.radiance_sum().size(); ++i)
        differ += a.radiance_sum()[i].x != b.radiance_sum()[i].x || a.radiance_sum()[i].y != b.radiance_sum()[i].y ||
                  a.radiance_sum()[i].z != b.radiance_sum()[i].z || a.radiance_sq_sum()[i].x != b.radiance_sq_sum()[i].x;
    EXPECT_EQ(differ, 0u);
}

struct Case {
    const char* name;
    Allocation allocation;
    Estimator estimator;
    double noise;
};

}  // namespace

// Stopped after k passes (before the adaptive warm-up, inside it, after the noise rule's
// first mask), through the bytes of a checkpoint, then on to the end: the same state as
// never stopping.
TEST(Checkpoint, ResumedRenderIsTheUninterruptedOne) {
    const Scene authored = test::brief_scene(6, 16);
    const RenderScene scene = prepare_scene(authored);
    for (const Case& c : {Case{"uniform", Allocation::uniform, Estimator::sobol, 0},
                          Case{"adaptive", Allocation::adaptive, Estimator::sobol, 0},
                          Case{"adaptive noise", Allocation::adaptive, Estimator::sobol, 0.05},
                          Case{"stratified", Allocation::uniform, Estimator::stratified, 0}}) {
        SCOPED_TRACE(c.name);
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.allocation = c.allocation;
        settings.estimator = c.estimator;
        settings.target_spp = 36;
        StopRule rule;
        rule.max_passes = 36;
        rule.noise = c.noise;
        rule.min_samples = 8;
        RenderState whole(16, 16);
        render_until(scene, settings, whole, rule);
        ASSERT_EQ(whole.passes, 36);
        // The noise rule's mask and the allocation's carried fractions are in play.
        EXPECT_EQ(whole.plan.active.empty(), c.noise == 0);
        EXPECT_EQ(whole.plan.sample_credit.empty(), c.allocation == Allocation::uniform);
        const CheckpointKey key = checkpoint_key(authored, scene, settings, rule);
        for (int k : {3, 10, 25}) {
            StopRule first = rule;
            first.max_passes = k;
            RenderState part(16, 16);
            render_until(scene, settings, part, first);
            RenderState resumed;
            decode_checkpoint(encode_checkpoint(key, part), "part.ckpt", key, resumed);
            render_until(scene, settings, resumed, rule);
            expect_same_state(whole, resumed);
        }
    }
}

// As the command line takes them: written after a pass (render_until's on_pass), at the
// noise rule's checks too, the last one (which meets the target) included. The resumed render
// stops where the uninterrupted one stops, for the same reason, with the same state.
TEST(Checkpoint, TakenAfterANoiseCheckResumesExactly) {
    const Scene authored = test::brief_scene(6, 16);
    const RenderScene scene = prepare_scene(authored);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.target_spp = 200;
    StopRule rule;
    rule.max_passes = 200;
    rule.noise = 0.1;
    rule.min_samples = 8;
    RenderState whole(16, 16);
    ASSERT_EQ(render_until(scene, settings, whole, rule), StopReason::noise);
    const int last = whole.passes;
    ASSERT_GE(last, 16);  // so at least one check before the last one did not meet the target
    const CheckpointKey key = checkpoint_key(authored, scene, settings, rule);
    for (int k : {last - 4, last - 1, last}) {
        SCOPED_TRACE(k);
        RenderState part(16, 16);
        std::string bytes;
        const StopReason first = render_until(scene, settings, part, rule, [&](const RenderState& s) {
            if (s.passes < k) return true;
            bytes = encode_checkpoint(key, s);
            return false;
        });
        ASSERT_EQ(first, StopReason::cancelled);
        RenderState resumed;
        decode_checkpoint(bytes, "part.ckpt", key, resumed);
        EXPECT_EQ(render_until(scene, settings, resumed, rule), StopReason::noise);
        expect_same_state(whole, resumed);
    }
}

// Each refusal is one line naming the file and what differs; the state is left untouched.
TEST(Checkpoint, RefusesAnotherSceneSettingsSizeOrDamage) {
    const Scene authored = test::brief_scene(6, 8);
    const RenderScene scene = prepare_scene(authored);
    const RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    StopRule rule;
    rule.max_passes = 2;
    RenderState state(8, 8);
    render_until(scene, settings, state, rule);
    const CheckpointKey key = checkpoint_key(authored, scene, settings, rule);
    const std::string bytes = encode_checkpoint(key, state);

    auto refusal = [&](const std::string& file_bytes, const CheckpointKey& expected) -> std::string {
        RenderState target(8, 8);
        try {
            decode_checkpoint(file_bytes, "run/r.ckpt", expected, target);
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(target.passes, 0);
            return e.what();
        }
        return "(accepted)";
    };
    auto expect_refused = [&](const std::string& message, const std::string& what) {
        EXPECT_EQ(message.rfind("run/r.ckpt: ", 0), 0u) << message;
        EXPECT_NE(message.find(what), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    };
    EXPECT_EQ(refusal(bytes, key), "(accepted)");

    Scene moved = authored;
    moved.renderer.depth += 1;
    expect_refused(refusal(bytes, checkpoint_key(moved, scene, settings, rule)), "another scene");
    // Where the image goes and its tone map do not change a sample: still accepted.
    Scene renamed = authored;
    renamed.renderer.output = "elsewhere.ppm";
    EXPECT_EQ(refusal(bytes, checkpoint_key(renamed, scene, settings, rule)), "(accepted)");

    RenderSettings other = settings;
    other.seed = 7;
    expect_refused(refusal(bytes, checkpoint_key(authored, scene, other, rule)), "the seed (--seed): 0 in the checkpoint, 7 here");
    StopRule noisier = rule;
    noisier.noise = 0.5;
    expect_refused(refusal(bytes, checkpoint_key(authored, scene, settings, noisier)),
                   "the noise rule's target (--noise): none in the checkpoint, 0.5 here");
    // The pass limit, an open-ended render's implicit cap included, named as such; every
    // setting that differs is named (a --noise render without --spp: both).
    StopRule capped = rule;
    capped.max_passes = 65536;
    expect_refused(refusal(bytes, checkpoint_key(authored, scene, settings, capped)),
                   "the pass limit (--spp): 2 in the checkpoint, 65536 (the cap of a --time or --noise render without "
                   "--spp) here");
    capped.noise = 0.01;
    const std::string both = refusal(bytes, checkpoint_key(authored, scene, settings, capped));
    expect_refused(both, "the pass limit (--spp): 2 in the checkpoint, 65536 (the cap");
    expect_refused(both, "; the noise rule's target (--noise): none in the checkpoint, 0.01 here");
    EXPECT_EQ(both.find("passes="), std::string::npos) << both;
    StopRule timed = rule;
    timed.seconds = 5;  // more or less time goes on to the same samples
    EXPECT_EQ(refusal(bytes, checkpoint_key(authored, scene, settings, timed)), "(accepted)");

    Scene larger = authored;
    larger.renderer.width = 9;
    expect_refused(refusal(bytes, checkpoint_key(larger, scene, settings, rule)), "checkpoint of a 8x8 image; this render is 9x8");

    expect_refused(refusal(bytes.substr(0, bytes.size() / 2), key), "checksum");
    std::string flipped = bytes;
    flipped[flipped.size() / 2] ^= 1;
    expect_refused(refusal(flipped, key), "checksum");
    std::string newer = bytes;
    newer[20] = 9;  // the version, after the 20-byte magic
    expect_refused(refusal(newer, key), "version 9");
    expect_refused(refusal("P6 1 1 255\n...", key), "not a keithray checkpoint");
}

// A checkpoint whose checksum holds but whose numbers no render writes (edited, or written
// by a faulty program) is refused naming the file and the first such pixel: NaN would
// otherwise reach every layer of the image. Sums of squares that overflowed to +inf are
// what a render of radiance above 1e154 writes: accepted.
TEST(Checkpoint, RefusesNumbersNoRenderWrites) {
    const Scene authored = test::brief_scene(6, 8);
    const RenderScene scene = prepare_scene(authored);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.target_spp = 12;
    StopRule rule;
    rule.max_passes = 12;
    rule.noise = 1e-3;  // never met: the noise rule's mask
    rule.min_samples = 8;
    RenderState state(8, 8);
    state.track_halves();  // the denoiser's halves
    render_until(scene, settings, state, rule);
    ASSERT_FALSE(state.plan.active.empty());
    ASSERT_FALSE(state.plan.sample_credit.empty());
    const CheckpointKey key = checkpoint_key(authored, scene, settings, rule);
    const size_t at = 2 * 8 + 5;  // pixel (5, 2)
    ASSERT_GE(state.sample_count()[at], 2u);
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();

    auto decoded = [&](const std::function<void(RenderState&)>& change) -> std::string {
        RenderState edited = state;
        change(edited);
        RenderState target(8, 8);
        try {
            decode_checkpoint(encode_checkpoint(key, edited), "run/r.ckpt", key, target);
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(target.passes, 0);
            return e.what();
        }
        return "(accepted)";
    };
    // A change to the film's sums (the plan's cases change the state's plan).
    const auto sums = [](std::function<void(PixelBuffers&)> change) {
        return std::function<void(RenderState&)>([change](RenderState& s) { change(s.buffers()); });
    };
    EXPECT_EQ(decoded([](RenderState&) {}), "(accepted)");
    EXPECT_EQ(decoded(sums([&](PixelBuffers& px) { px.radiance_sq_sum[at].y = px.luminance_sq_sum[at] = inf; })), "(accepted)");
    const std::pair<const char*, std::function<void(RenderState&)>> cases[] = {
        {"radiance sum (0.5, nan,", sums([&](PixelBuffers& px) { px.radiance_sum[at] = Color(0.5, nan, 0.5); })},
        {"radiance sum (inf,", sums([&](PixelBuffers& px) { px.radiance_sum[at].x = inf; })},
        {"compensation", sums([&](PixelBuffers& px) { px.radiance_compensation[at].z = nan; })},
        {"sum of squared radiance", sums([&](PixelBuffers& px) { px.radiance_sq_sum[at].x = -1; })},
        {"sum of squared luminance nan", sums([&](PixelBuffers& px) { px.luminance_sq_sum[at] = nan; })},
        {"sum of depths -3", sums([&](PixelBuffers& px) { px.depth_sum[at] = -3; })},
        {"samples accumulated but", sums([&](PixelBuffers& px) { px.sample_count[at] = px.sample_index[at] + 1; })},
        {"samples drawn in 12 passes (at most 64 a pass)", sums([&](PixelBuffers& px) { px.sample_index[at] = 12 * 64 + 1; })},
        {"sums without a sample", sums([&](PixelBuffers& px) { px.sample_count[at] = 0, px.half_count[at] = 0; })},
        {"mask is 7", [&](RenderState& s) { s.plan.active[at] = 7; }},
        {"carried fraction of a sample nan", [&](RenderState& s) { s.plan.sample_credit[at] = float(nan); }},
        {"carried fraction of a sample -1", [&](RenderState& s) { s.plan.sample_credit[at] = -1; }},
        {"half's radiance sum", sums([&](PixelBuffers& px) { px.half_sum[at].y = inf; })},
        {"a half of", sums([&](PixelBuffers& px) { px.half_count[at] = px.sample_count[at] + 1; })},
    };
    for (const auto& [what, change] : cases) {
        const std::string message = decoded(change);
        EXPECT_EQ(message.rfind("run/r.ckpt: checkpoint holds numbers no render writes", 0), 0u) << what << ": " << message;
        EXPECT_NE(message.find("pixel (5, 2): "), std::string::npos) << what << ": " << message;
        EXPECT_NE(message.find(what), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
    // The first bad pixel, row by row.
    const std::string first = decoded(sums([&](PixelBuffers& px) {
        px.radiance_sum[at].x = nan;
        px.depth_sum[at + 9] = nan;
        px.depth_sum[3] = -1;
    }));
    EXPECT_NE(first.find("pixel (3, 0): its sum of depths -1"), std::string::npos) << first;
}

namespace {

class CheckpointCli : public test::ScratchDirTest {
protected:
    // A small copy of scene 6 (path tracing, glass and an area light) in the scratch folder.
    fs::path small_scene(int size) {
        Scene scene = test::brief_scene(6, size);
        scene.renderer.output = (dir / "out.ppm").string();  // beside the scene file
        const fs::path file = dir / "scene.json";
        save_scene_json(scene, file);
        return file;
    }
    // keithray run in the scratch folder (relative outputs and checkpoints land there).
    test::CommandResult cli_here(const std::string& args) {
        return test::run_command("cd '" + dir.string() + "' && '" + KEITHRAY_EXE + "' " + args, dir);
    }
};

}  // namespace

// SIGINT during a checkpointed render: exit 130, no image, a checkpoint; --resume then
// writes the bytes of the render never interrupted.
TEST_F(CheckpointCli, InterruptedAndResumedIsByteForByteTheWholeRender) {
    const fs::path scene = small_scene(48);
    const std::string common = "render '" + scene.string() + "' --spp 3000 -q --threads 1 ";
    ASSERT_EQ(cli_here(common + "-o whole.ppm").status, 0);

    const fs::path checkpoint = dir / "r.ckpt";
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        const std::string cmd = "cd '" + dir.string() + "' && exec '" + std::string(KEITHRAY_EXE) + "' " + common +
                                "-o cut.ppm --checkpoint r.ckpt --every 0 2>cut.err";
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    // The first checkpoint is written after the first pass; the signal comes after it.
    for (int i = 0; i < 60000 && !fs::exists(checkpoint); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << status;
    ASSERT_EQ(WEXITSTATUS(status), 130) << "the render ended before the signal: " << test::read_file(dir / "cut.err");
    EXPECT_NE(test::read_file(dir / "cut.err").find("stopped by a signal"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir / "cut.ppm"));
    EXPECT_FALSE(fs::exists(dir / "cut-depth.ppm"));

    const test::CommandResult resumed = cli_here(common + "-o cut.ppm --resume r.ckpt");
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_EQ(test::read_file(dir / "cut.ppm"), test::read_file(dir / "whole.ppm"));
    EXPECT_EQ(test::read_file(dir / "cut-depth.ppm"), test::read_file(dir / "whole-depth.ppm"));

    // Another seed: refused, one line naming the flag, the file and the difference.
    const test::CommandResult refused = cli_here(common + "--seed 3 -o other.ppm --resume r.ckpt");
    EXPECT_EQ(refused.status, 1);
    EXPECT_EQ(refused.err, "error: --resume r.ckpt: checkpoint of other settings: the seed (--seed): 0 in the checkpoint, "
                           "3 here; nothing rendered\n");
    EXPECT_FALSE(fs::exists(dir / "other.ppm"));
}

TEST_F(CheckpointCli, FlagsAreChecked) {
    const fs::path scene = small_scene(8);
    EXPECT_EQ(cli_here("render '" + scene.string() + "' '" + scene.string() + "' --checkpoint c.ckpt").status, 2);
    EXPECT_EQ(cli_here("render '" + scene.string() + "' --every -1 --checkpoint c.ckpt").status, 2);
    // The checkpoint never replaces the scene file or an output.
    const std::string before = test::read_file(scene);
    const test::CommandResult onto_scene = cli_here("render scene.json -q --checkpoint scene.json --every 0");
    EXPECT_EQ(onto_scene.status, 1);
    EXPECT_EQ(onto_scene.err, "error: --checkpoint scene.json would overwrite scene.json; nothing written\n");
    EXPECT_EQ(test::read_file(scene), before);
    EXPECT_EQ(cli_here("render scene.json -q -o x.ppm --checkpoint x-depth.ppm").status, 1);
    EXPECT_FALSE(fs::exists(dir / "x.ppm"));
    const test::CommandResult missing = cli_here("render '" + scene.string() + "' -q --resume nowhere.ckpt");
    EXPECT_EQ(missing.status, 1);
    EXPECT_NE(missing.err.find("nowhere.ckpt"), std::string::npos) << missing.err;
}

namespace {

// keithray started in `dir` with KEITHRAY_TEST_STOP_BEFORE_RENAME=`hook` (core/file_write.cpp):
// it stops itself inside the chosen write, every temporary whole and none renamed. Returns
// the child, stopped there (or -1 if it ended first, `status` then holds how).
pid_t start_stopped_in_write(const fs::path& dir, const std::string& args, const std::string& hook, int& status) {
    const pid_t child = ::fork();
    if (child == 0) {
        ::setenv("KEITHRAY_TEST_STOP_BEFORE_RENAME", hook.c_str(), 1);
        ::signal(SIGINT, SIG_DFL);  // whatever the test runner's dispositions
        ::signal(SIGTERM, SIG_DFL);
        const std::string cmd = "cd '" + dir.string() + "' && exec '" + std::string(KEITHRAY_EXE) + "' " + args +
                                " >out.txt 2>err.txt";
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    if (::waitpid(child, &status, WUNTRACED) != child || !WIFSTOPPED(status)) return -1;
    return child;
}

// Sends `signals` to the stopped child, lets it go on and returns its status.
int signal_and_wait(pid_t child, std::initializer_list<int> signals) {
    for (int sig : signals) ::kill(child, sig);
    ::kill(child, SIGCONT);
    int status = 0;
    ::waitpid(child, &status, 0);
    return status;
}

bool has_temporary(const fs::path& dir) {
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().filename().string().find(".tmp") != std::string::npos) return true;
    return false;
}

}  // namespace

// A signal while a checkpoint is being written: the write completes (the new checkpoint is
// whole), the render stops as documented (exit 128 + signal, no image, "holds them") with no
// "checkpoint not written" warning, and --resume finishes the uninterrupted render's bytes.
TEST_F(CheckpointCli, SignalDuringACheckpointWriteKeepsItWholeAndStops) {
    const fs::path scene = small_scene(24);
    const std::string common = "render '" + scene.string() + "' --spp 40 -q --threads 1 ";
    ASSERT_EQ(cli_here(common + "-o whole.ppm").status, 0);
    for (int sig : {SIGTERM, SIGINT}) {
        fs::remove(dir / "r.ckpt");
        int status = 0;
        const pid_t child = start_stopped_in_write(dir, common + "-o cut.ppm --checkpoint r.ckpt --every 0", "r.ckpt:2", status);
        ASSERT_GT(child, 0) << "ended before its second checkpoint: " << status << test::read_file(dir / "err.txt");
        status = signal_and_wait(child, {sig});
        const std::string err = test::read_file(dir / "err.txt");
        ASSERT_TRUE(WIFEXITED(status)) << status << err;
        EXPECT_EQ(WEXITSTATUS(status), 128 + sig) << err;
        EXPECT_NE(err.find("stopped by a signal"), std::string::npos) << err;
        EXPECT_NE(err.find("holds them (go on with --resume)"), std::string::npos) << err;
        EXPECT_EQ(err.find("not written"), std::string::npos) << err;
        EXPECT_FALSE(fs::exists(dir / "cut.ppm"));
        EXPECT_FALSE(has_temporary(dir));
        const test::CommandResult resumed = cli_here(common + "-o cut.ppm --resume r.ckpt");
        ASSERT_EQ(resumed.status, 0) << resumed.err;
        EXPECT_EQ(test::read_file(dir / "cut.ppm"), test::read_file(dir / "whole.ppm"));
        fs::remove(dir / "cut.ppm");
        fs::remove(dir / "cut-depth.ppm");
    }
}

// A second signal during that write ends the run at once: the temporary is removed and the
// previous checkpoint stays whole (it resumes to the same bytes).
TEST_F(CheckpointCli, SecondSignalDuringACheckpointWriteLeavesTheOldOneWhole) {
    const fs::path scene = small_scene(24);
    const std::string common = "render '" + scene.string() + "' --spp 40 -q --threads 1 ";
    ASSERT_EQ(cli_here(common + "-o whole.ppm").status, 0);
    int status = 0;
    const pid_t child = start_stopped_in_write(dir, common + "-o cut.ppm --checkpoint r.ckpt --every 0", "r.ckpt:3", status);
    ASSERT_GT(child, 0) << status;
    const std::string old = test::read_file(dir / "r.ckpt");
    status = signal_and_wait(child, {SIGINT, SIGTERM});
    EXPECT_TRUE(WIFSIGNALED(status)) << status;
    EXPECT_FALSE(has_temporary(dir));
    EXPECT_EQ(test::read_file(dir / "r.ckpt"), old);
    EXPECT_FALSE(fs::exists(dir / "cut.ppm"));
    const test::CommandResult resumed = cli_here(common + "-o cut.ppm --resume r.ckpt");
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_EQ(test::read_file(dir / "cut.ppm"), test::read_file(dir / "whole.ppm"));
}

// --denoise: the checkpoint holds the final denoiser's two halves of the samples, so the
// resumed render's denoised image is the uninterrupted one's, float for float; a checkpoint
// without them (rendered without --denoise) is refused with --denoise, one line.
TEST_F(CheckpointCli, DenoisedRenderResumesToTheWholeRendersBytes) {
    const fs::path scene = small_scene(12);
    const std::string plain = "render '" + scene.string() + "' --spp 40 -q --threads 1 ", denoised = plain + "--denoise ";
    // The render of `args` stopped by SIGTERM during its second checkpoint's write.
    auto stop_at_second_checkpoint = [&](const std::string& args, const std::string& checkpoint) {
        int status = 0;
        const pid_t child = start_stopped_in_write(dir, args + " --checkpoint " + checkpoint + " --every 0",
                                                   checkpoint + ":2", status);
        ASSERT_GT(child, 0) << status << test::read_file(dir / "err.txt");
        status = signal_and_wait(child, {SIGTERM});
        ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGTERM) << status << test::read_file(dir / "err.txt");
    };
    ASSERT_EQ(cli_here(denoised + "-o whole.pfm").status, 0);
    stop_at_second_checkpoint(denoised + "-o cut.pfm", "r.ckpt");
    ASSERT_FALSE(fs::exists(dir / "cut.pfm"));
    const test::CommandResult resumed = cli_here(denoised + "-o cut.pfm --resume r.ckpt");
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_EQ(resumed.err, "");
    EXPECT_EQ(test::read_file(dir / "cut.pfm"), test::read_file(dir / "whole.pfm"));

    stop_at_second_checkpoint(plain + "-o raw.pfm", "raw.ckpt");
    const test::CommandResult refused = cli_here(denoised + "-o other.pfm --resume raw.ckpt");
    EXPECT_EQ(refused.status, 1);
    EXPECT_EQ(refused.err, "error: --resume raw.ckpt: checkpoint of a render without --denoise: "
                           "it lacks the two halves of the samples that --denoise reads; nothing rendered\n");
    EXPECT_FALSE(fs::exists(dir / "other.pfm"));
    // Without --denoise it goes on as before.
    EXPECT_EQ(cli_here(plain + "-o raw.pfm --resume raw.ckpt").status, 0);
}

// The image is written after checkpoints were: a signal inside that write still finds the
// cleanup handler (the render's stop handling ended with its passes): no temporary, the old
// image untouched, the checkpoint whole, the process ended by the signal.
TEST_F(CheckpointCli, SignalDuringTheImageWriteAfterCheckpointsLeavesNoTemporary) {
    const fs::path scene = small_scene(24);
    const std::string common = "render '" + scene.string() + "' --spp 4 -q --threads 1 ";
    for (int sig : {SIGTERM, SIGINT}) {
        fs::remove(dir / "r.ckpt");
        {
            std::ofstream old(dir / "cut.ppm");
            old << "old";
        }
        int status = 0;
        const pid_t child = start_stopped_in_write(dir, common + "-o cut.ppm --checkpoint r.ckpt --every 0", "cut.ppm:1", status);
        ASSERT_GT(child, 0) << status;
        status = signal_and_wait(child, {sig});
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status << test::read_file(dir / "err.txt");
        EXPECT_FALSE(has_temporary(dir));
        EXPECT_EQ(test::read_file(dir / "cut.ppm"), "old");
        EXPECT_FALSE(fs::exists(dir / "cut-depth.ppm"));
        const test::CommandResult resumed = cli_here(common + "-o done.ppm --resume r.ckpt");
        EXPECT_EQ(resumed.status, 0) << resumed.err;
    }
}

// An open-ended render (--time or --noise without --spp) runs up to the cap of 65536
// passes: resumed plainly it would end at the scene's spp instead, another image. Refused,
// naming the pass limit; resumed with its --noise it goes on.
TEST_F(CheckpointCli, OpenEndedRenderResumedPlainlyIsRefused) {
    const fs::path scene = small_scene(8);
    const std::string common = "render '" + scene.string() + "' -q --threads 1 -o out.ppm ";
    const test::CommandResult first = cli_here(common + "--noise 0.5 --checkpoint r.ckpt --every 0");
    ASSERT_EQ(first.status, 0) << first.err;
    const test::CommandResult refused = cli_here(common + "--resume r.ckpt");
    EXPECT_EQ(refused.status, 1);
    EXPECT_NE(refused.err.find("the pass limit (--spp): 65536 (the cap of a --time or --noise render without --spp) "
                               "in the checkpoint"),
              std::string::npos)
        << refused.err;
    EXPECT_NE(refused.err.find("the noise rule's target (--noise): 0.5 in the checkpoint, none here"), std::string::npos)
        << refused.err;
    // A --time render likewise (it may have stopped by its time or at the cap).
    ASSERT_EQ(cli_here(common + "--time 0.2 --checkpoint t.ckpt --every 0").status, 0);
    const test::CommandResult timed = cli_here(common + "--resume t.ckpt");
    EXPECT_EQ(timed.status, 1);
    EXPECT_NE(timed.err.find("the pass limit (--spp): 65536 (the cap"), std::string::npos) << timed.err;
    // The other way round, the case: a render of a pass limit resumed with a noise rule.
    ASSERT_EQ(cli_here(common + "--spp 3 --checkpoint s.ckpt --every 0").status, 0);
    const test::CommandResult noisy = cli_here(common + "--noise 0.5 --resume s.ckpt");
    EXPECT_EQ(noisy.status, 1);
    EXPECT_NE(noisy.err.find("the noise rule's target (--noise): none in the checkpoint, 0.5 here"), std::string::npos)
        << noisy.err;
    const test::CommandResult again = cli_here(common + "--noise 0.5 --resume r.ckpt");
    EXPECT_EQ(again.status, 0) << again.err;
}

// The checkpoint's target is checked before the render, like the images': a folder, a
// device, a read-only file; one line, exit 1, nothing rendered or written.
TEST_F(CheckpointCli, CheckpointTargetIsCheckedBeforeRendering) {
    const fs::path scene = small_scene(8);
    fs::create_directories(dir / "folder");
    {
        std::ofstream ro(dir / "ro.ckpt");
        ro << "old";
    }
    fs::permissions(dir / "ro.ckpt", fs::perms::owner_read);
    for (const std::string target : {"folder", "/dev/null", "ro.ckpt"}) {
        const test::CommandResult r = cli_here("render scene.json -q -o out.ppm --spp 2 --checkpoint " + target);
        EXPECT_EQ(r.status, 1) << target;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find("nothing rendered"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir / "out.ppm")) << target;
    }
    EXPECT_EQ(test::read_file(dir / "ro.ckpt"), "old");
}

// The case on the command line: a checkpoint with a valid checksum whose first
// pixel's radiance sum is NaN. Resuming refuses it, one line naming the file and the pixel;
// no image is written (it would be NaN in every layer).
TEST_F(CheckpointCli, CheckpointWithNanSumsIsRefusedNamingThePixel) {
    small_scene(8);
    const std::string common = "render scene.json -q --threads 1 --spp 4 ";
    ASSERT_EQ(cli_here(common + "-o first.exr --checkpoint r.ckpt --every 0").status, 0);
    std::string bytes = test::read_file(dir / "r.ckpt");
    // The layout of render/checkpoint.h: magic, version, scene, key length and key, width,
    // height, passes, rays, non-finite count, then the first pixel's radiance sum.
    size_t at = 20 + 4 + 8;
    uint32_t key_length = 0;
    std::memcpy(&key_length, bytes.data() + at, 4);
    at += 4 + key_length + 4 + 4 + 4 + 8 + 8;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::memcpy(bytes.data() + at + sizeof(double), &nan, sizeof nan);  // its green
    const uint64_t checksum = fnv1a(std::string_view(bytes).substr(0, bytes.size() - 8));
    std::memcpy(bytes.data() + bytes.size() - 8, &checksum, 8);
    std::ofstream(dir / "nan.ckpt", std::ios::binary) << bytes;
    const test::CommandResult r = cli_here(common + "-o resumed.exr --resume nan.ckpt");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("nan.ckpt: checkpoint holds numbers no render writes"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("pixel (0, 0): its radiance sum ("), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "resumed.exr"));
    // The untouched checkpoint resumes.
    EXPECT_EQ(cli_here(common + "-o resumed.exr --resume r.ckpt").status, 0);
}
