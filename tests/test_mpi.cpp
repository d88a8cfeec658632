// keithray under mpirun (issues 26 and 36; app/cluster.h): the bytes of the render without
// MPI at 1 to 4 ranks for every integrator, estimator and allocation and the noise rule, also
// where a rank owns one row or none; the checkpoint of one process at any rank count; each
// rank's memory check of the rows it holds; each
// rank receives only its rows' neighbours and the per-row sums between passes; a plain run
// never starts MPI; a bad scene
// ends every rank with one error line; a rank killed mid-render ends the job non-zero with no
// image and a checkpoint that resumes to the uninterrupted image. Every run is under
// `timeout`: a hang fails the test instead of the suite.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "core/memory.h"
#include "render/outputs.h"
#include "render/render_state.h"
#include "scene/save.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

constexpr int kTimeoutSeconds = 300;

class Mpi : public test::ScratchDirTest {
protected:
    void SetUp() override {
        test::ScratchDirTest::SetUp();
        if (!KEITHRAY_MPI_BUILT) GTEST_SKIP() << "keithray was built without MPI (libopenmpi-dev absent at configure)";
        if (std::string(KEITHRAY_MPIEXEC).empty() || ::access(KEITHRAY_MPIEXEC, X_OK) != 0)
            GTEST_SKIP() << "no mpirun (openmpi-bin) to launch ranks";
    }
    // The launcher's command for `ranks` ranks of one OpenMP thread each, allowed on a small
    // machine (more ranks than cores, no binding) and as root.
    std::string mpirun(int ranks) const {
        return "timeout " + std::to_string(kTimeoutSeconds) + " '" + KEITHRAY_MPIEXEC + "' --oversubscribe --bind-to none " +
               (::geteuid() == 0 ? "--allow-run-as-root " : "") + "-x OMP_NUM_THREADS=1 -np " + std::to_string(ranks) +
               " '" + KEITHRAY_EXE + "' ";
    }
    // Runs `command` in the scratch folder.
    test::CommandResult here(const std::string& command) {
        return test::run_command("cd '" + dir.string() + "' && " + command, dir);
    }
    std::string keithray() const { return std::string("timeout ") + std::to_string(kTimeoutSeconds) + " '" + KEITHRAY_EXE + "' "; }
    // Scene `n` of the brief at size x size pixels (size x height), written to the scratch folder.
    std::string scene(int n, int size, const std::string& name, const std::string& output = "out.ppm", int height = 0) {
        Scene s = test::brief_scene(n, size);
        if (height > 0) s.renderer.height = height;
        s.renderer.output = (dir / output).string();  // beside the scene file
        save_scene_json(s, dir / name);
        return name;
    }
    // `args` rendered by one process of 2 threads, then by 1 to `max_ranks` ranks: the same bytes.
    void expect_same_bytes(const std::string& args, const std::string& output, int max_ranks = 4) {
        const test::CommandResult single = here(keithray() + "render -q --threads 2 " + args + " -o single-" + output);
        ASSERT_EQ(single.status, 0) << single.err;
        for (int ranks = 1; ranks <= max_ranks; ++ranks) {
            SCOPED_TRACE(ranks);
            const std::string out = std::to_string(ranks) + "-" + output;
            const test::CommandResult r = here(mpirun(ranks) + "render -q " + args + " -o " + out);
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(bytes(out), bytes("single-" + output));
            const std::string stem = output.substr(0, output.rfind('.'));
            if (output.ends_with(".ppm"))
                EXPECT_EQ(bytes(std::to_string(ranks) + "-" + stem + "-depth.ppm"), bytes("single-" + stem + "-depth.ppm"));
            // Rank 0 prints the summary once, with each rank's busy time.
            EXPECT_NE(r.out.find(std::to_string(ranks) + " ranks: busy s"), std::string::npos) << r.out;
        }
    }
    // How many passes the noise rule took, from the stop line of a run's stderr (-1: none).
    static int noise_passes(const std::string& err) {
        const size_t at = err.find("stopped by --noise after ");
        return at == std::string::npos ? -1 : std::stoi(err.substr(at + 25));
    }
    std::string bytes(const std::string& name) { return test::read_file(dir / name); }

    // The viewer's window runs under xvfb-run, as tests/test_viewer_window.cpp's do: -n starts
    // the free-display search at a number of this process's and call's, -noreset keeps the
    // exit status keithray's.
    static bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }
    static std::string xvfb_run() {
        static int calls = 0;
        const int start = 300 + int((unsigned(::getpid()) * 89u + unsigned(calls++) * 17u) % 20000u);
        return "xvfb-run -a -n " + std::to_string(start) + " -s '-screen 0 1280x1024x24 -noreset' ";
    }
    // `keithray view` with `args` in one process, then under mpirun at each of `ranks`: the
    // image saved (every EXR layer, developed by Save's final denoiser, which reads the two
    // halves of the samples) and the screenshot of the display are the same bytes.
    void expect_viewer_same_bytes(const std::string& args, std::initializer_list<int> ranks) {
        const test::CommandResult single =
            here(xvfb_run() + keithray() + "view " + args + " --save-image single.exr --screenshot single-shot.ppm");
        ASSERT_EQ(single.status, 0) << single.err;
        for (int n : ranks) {
            SCOPED_TRACE(n);
            const std::string name = std::to_string(n);
            const test::CommandResult r = here(xvfb_run() + mpirun(n) + "view " + args + " --save-image " + name +
                                               ".exr --screenshot " + name + "-shot.ppm");
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(bytes(name + ".exr"), bytes("single.exr"));
            EXPECT_EQ(bytes(name + "-shot.ppm"), bytes("single-shot.ppm"));
        }
    }
};

}  // namespace

TEST_F(Mpi, SameBytesAtOneToFourRanks) {
    const std::string wrt = scene(1, 32, "wrt.json"), pt = scene(6, 32, "pt.json");
    struct Case {
        const char* name;
        std::string args, output;
    };
    for (const Case& c : {Case{"wrt uniform", wrt + " --spp 6 --allocation uniform", "a.ppm"},
                          Case{"pt uniform", pt + " --spp 10 --allocation uniform", "a.ppm"},
                          Case{"pt uniform sobol", pt + " --spp 10 --allocation uniform --estimator sobol", "a.ppm"},
                          Case{"pt adaptive", pt + " --spp 24 --estimator uniform", "a.ppm"},
                          Case{"pt adaptive sobol", pt + " --spp 24 --estimator sobol", "a.ppm"},
                          Case{"pt noise", pt + " --noise 0.03 --spp 400", "a.ppm"},
                          Case{"pt noise uniform allocation", pt + " --noise 0.03 --spp 400 --allocation uniform", "a.ppm"},
                          Case{"pt stratified, every layer", pt + " --spp 9 --estimator stratified", "a.exr"}}) {
        SCOPED_TRACE(c.name);
        // The noise rule stops it, after its mask has steered passes (from pass 16 on).
        if (c.args.find("--noise") != std::string::npos) {
            const test::CommandResult single = here(keithray() + "render -q " + c.args + " -o probe.ppm");
            EXPECT_GT(noise_passes(single.err), 16) << single.err;
        }
        expect_same_bytes(c.args, c.output);
    }
}

// `render --denoise`: each rank keeps its rows' two halves of the samples and the gather
// brings them to rank 0, so the final filter (which cross-filters the halves) develops one
// process's image at 1 to 4 ranks: the PNG-like PPM, and the EXR's denoised, raw and feature
// layers, with adaptive passes and a rank owning no row (3 rows at 4 ranks). A checkpoint of
// the denoised render keeps the halves: resumed at 2 and 3 ranks (each rank receives its
// rows' halves) it develops the same image.
TEST_F(Mpi, DenoisedRenderIsOneProcesssAtAnyRankCount) {
    const std::string pt = scene(6, 24, "pt.json", "out.ppm", 19), rows = scene(6, 7, "rows.json", "out.ppm", 3);
    expect_same_bytes(pt + " --spp 12 --denoise", "d.ppm");
    expect_same_bytes(pt + " --spp 9 --estimator stratified --denoise", "d.exr");
    expect_same_bytes(rows + " --spp 10 --denoise", "r.ppm");
    const std::string args = "render -q " + pt + " --spp 8 --denoise --every 0 ";
    const test::CommandResult single = here(keithray() + args + "--threads 2 -o single.ppm --checkpoint d.ckpt");
    ASSERT_EQ(single.status, 0) << single.err;
    for (int ranks : {2, 3}) {
        SCOPED_TRACE(ranks);
        const test::CommandResult r = here(mpirun(ranks) + args + "-o resumed.ppm --resume d.ckpt");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(r.err.find("note:"), std::string::npos) << r.err;
        EXPECT_EQ(bytes("resumed.ppm"), bytes("single.ppm"));
    }
}

// Row partitions where a rank owns one row or none (3 rows at 4 ranks), unequal shares and
// odd sizes (5 rows of 7 pixels), with the adaptive plan and the noise rule reading the 3x3
// guard across the ranks' rows.
TEST_F(Mpi, SameBytesWhereARankOwnsOneRowOrNone) {
    for (int height : {3, 5}) {
        SCOPED_TRACE(height);
        const std::string s = scene(6, 7, "rows" + std::to_string(height) + ".json", "out.ppm", height);
        expect_same_bytes(s + " --spp 20", "adaptive.ppm");
        expect_same_bytes(s + " --spp 60 --noise 0.05 --estimator sobol", "noise.ppm");
    }
}

// A checkpoint of an image with fewer rows than ranks (1 and 2 rows at 4 ranks) resumes:
// a rank without rows receives none of rank 0's rows, where it waited for them for ever.
TEST_F(Mpi, ResumeWhereARankOwnsNoRow) {
    for (int height : {1, 2}) {
        SCOPED_TRACE(height);
        const std::string s = scene(6, 7, "rows" + std::to_string(height) + ".json", "out.ppm", height);
        const std::string args = "render -q " + s + " --spp 6 --every 0 ";
        const test::CommandResult single = here(keithray() + args + "--threads 2 -o single.ppm --checkpoint r.ckpt");
        ASSERT_EQ(single.status, 0) << single.err;
        for (int ranks : {2, 4}) {
            SCOPED_TRACE(ranks);
            const test::CommandResult r = here(mpirun(ranks) + args + "-o resumed.ppm --resume r.ckpt");
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(bytes("resumed.ppm"), bytes("single.ppm"));
        }
    }
}

// The checkpoint after the last pass of a render under the noise rule (its mask, set at pass
// 28, and the plan's carried fractions, both planned by each rank on its own rows) is the one
// process's file, byte for byte, at 2 to 4 ranks.
TEST_F(Mpi, CheckpointIsOneProcesssAtAnyRankCount) {
    const std::string s = scene(6, 24, "scene.json", "out.ppm", 19);
    const std::string args = "render -q " + s + " --spp 30 --noise 0.01 --every 0 ";
    const test::CommandResult single = here(keithray() + args + "--threads 2 -o single.ppm --checkpoint single.ckpt");
    ASSERT_EQ(single.status, 0) << single.err;
    ASSERT_EQ(noise_passes(single.err), -1) << single.err;  // the mask steered passes 17 to 30
    for (int ranks : {2, 3, 4}) {
        SCOPED_TRACE(ranks);
        const std::string name = std::to_string(ranks);
        const test::CommandResult r = here(mpirun(ranks) + args + "-o " + name + ".ppm --checkpoint " + name + ".ckpt");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(bytes(name + ".ckpt"), bytes("single.ckpt"));
        EXPECT_EQ(bytes(name + ".ppm"), bytes("single.ppm"));
    }
}

// Between passes a rank receives the rows next to its blocks (36 bytes a pixel, from the
// ranks owning the neighbouring blocks) and the per-row sums, not the whole image's
// statistics: at 4 ranks, 64x64, 24 spp (16 passes planned), the most a rank receives a pass
// is its guard rows (rows_guarded less its own: at most 2 per block) x 64 pixels x 36
// bytes, plus at most 64 rows x 2 sums x 8 bytes, under the 36 x 4096 x 3/4 bytes of the
// whole image's.
TEST_F(Mpi, RanksReceiveOnlyTheirNeighbourRowsAndRowSums) {
    scene(6, 64, "scene.json");
    const test::CommandResult r = here(mpirun(4) + "render -q scene.json --spp 24 -o out.ppm");
    ASSERT_EQ(r.status, 0) << r.err;
    const size_t at = r.out.find(" MB received after ");
    ASSERT_NE(at, std::string::npos) << r.out;
    const double megabytes = std::stod(r.out.substr(r.out.rfind(' ', at - 1) + 1));
    const int passes = std::stoi(r.out.substr(at + 19));
    EXPECT_EQ(passes, 24 - 8 + 1) << r.out;  // after passes 8 to 24 (the last for its summary)
    size_t guard = 0;
    for (int rank = 0; rank < 4; ++rank)
        guard = std::max(guard, rows_guarded(rank, 4, 64).size() - rows_owned(rank, 4, 64).size());
    EXPECT_GT(guard, 0u);
    EXPECT_LE(guard, 2u * kRowBlocks);
    const double per_pass = megabytes * 1e6 / passes;
    EXPECT_GT(per_pass, double(guard) * 64 * 36) << r.out;
    EXPECT_LE(per_pass, double(guard) * 64 * 36 + 64 * 2 * 8) << r.out;
}

// Rank 0 holds the whole state (it gathers it and writes the outputs); every other rank only
// its rows and their neighbours': the memory check of each says so, here refused under a
// 16 GiB address-space limit for a 32768x32768 image (each rank of 4 holds a quarter of the
// rows and at most 2 kRowBlocks more).
TEST_F(Mpi, EachRankChecksTheMemoryOfTheRowsItHolds) {
    scene(6, 32768, "huge.json");
    const test::CommandResult r = here("ulimit -v 16777216; " + mpirun(4) + "render -q huge.json -o huge.ppm");
    EXPECT_NE(r.status, 0);
    const std::string rank0 = "needs about " + format_bytes(render_memory_bytes(32768, 32768, false)) + ", above the "
                              "address-space limit (ulimit -v) (16.0 GiB) on rank 0";
    EXPECT_NE(r.err.find(rank0), std::string::npos) << r.err;
    for (int rank : {1, 2, 3}) {
        const size_t held = rows_guarded(rank, 4, 32768).size();
        EXPECT_LE(held, 32768 / 4 + 2 * kRowBlocks);
        const std::string others = "needs about " + format_bytes(render_state_bytes(32768, held));
        EXPECT_NE(r.err.find(others + ", above the address-space limit (ulimit -v) (16.0 GiB) on rank " +
                             std::to_string(rank)),
                  std::string::npos)
            << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "huge.ppm"));
}

// Run plainly (no launcher in the environment), keithray never calls MPI_Init: Open MPI's
// initialisation, even as a singleton, leaves its session folder (ompi.HOST.UID) in TMPDIR.
// Neither render nor view.
TEST_F(Mpi, PlainRunNeverStartsMpi) {
    scene(6, 16, "scene.json");
    fs::create_directories(dir / "tmp");
    const std::string plain = "env -u OMPI_COMM_WORLD_SIZE -u PMIX_RANK -u PMI_RANK TMPDIR='" + (dir / "tmp").string() + "' ";
    const test::CommandResult r = here(plain + keithray() + "render -q scene.json --spp 12 --noise 0.05 -o plain.ppm");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.find("ranks: busy"), std::string::npos) << r.out;
    if (have_xvfb()) {
        // TMPDIR for keithray alone: xvfb-run keeps its own files there while it runs.
        const test::CommandResult v =
            here(xvfb_run() + plain + keithray() + "view scene.json --spp 4 --frames 4 --screenshot view.ppm --timeout 240");
        ASSERT_EQ(v.status, 0) << v.err;
        EXPECT_TRUE(fs::exists(dir / "view.ppm"));
    }
    for (const auto& entry : fs::directory_iterator(dir / "tmp")) ADD_FAILURE() << "MPI started: " << entry.path();
}

// `mpirun -np N keithray view`: rank 0's window shows the single-process viewer's image at
// N passes, bit for bit, at 1 to 4 ranks: adaptive passes (planned from pass 9 on, reading
// the guard rows across ranks), 3 rows at 4 ranks (one rank owns none), and a render region.
TEST_F(Mpi, ViewerImageIsOneProcesssAtOneToFourRanks) {
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (scripts/setup.sh installs it)";
    scene(6, 24, "scene.json", "out.ppm", 19);
    expect_viewer_same_bytes("scene.json --spp 12 --frames 12 --timeout 240", {1, 2, 3, 4});
    scene(6, 7, "rows.json", "out.ppm", 3);
    expect_viewer_same_bytes("rows.json --spp 10 --frames 10 --timeout 240", {4});
    expect_viewer_same_bytes("scene.json --spp 12 --frames 12 --region 3,2 17,15 --estimator stratified --timeout 240",
                             {3});
}

// Edits reach every rank: three orbit nudges, each made while full passes shared by the
// ranks run (--measure-latency waits for a full-resolution frame before each), then the
// passes of the edited view are the single-process viewer's after the same edits.
TEST_F(Mpi, ViewerEditReachesEveryRank) {
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (scripts/setup.sh installs it)";
    scene(6, 24, "scene.json", "out.ppm", 19);
    expect_viewer_same_bytes("scene.json --spp 16 --frames 16 --measure-latency 3 --timeout 240", {2, 3});
}

// A rank killed while the ranks render: rank 0's window says the job is ending (and its
// standard error), and the job ends non-zero at once instead of waiting on the dead rank.
TEST_F(Mpi, ViewerRankKilledEndsTheSessionWithAMessage) {
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (scripts/setup.sh installs it)";
    scene(6, 24, "scene.json", "out.ppm", 19);
    const pid_t launcher = ::fork();
    ASSERT_GE(launcher, 0);
    if (launcher == 0) {
        const std::string cmd = "cd '" + dir.string() + "' && exec " + xvfb_run() + mpirun(3) +
                                "view scene.json --spp 1000000 --frames 1000000 --status-file status.txt "
                                "--timeout 250 2>killed.err >killed.out";
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    // Until the ranks have shared a few passes.
    auto spp = [&] {
        const std::string line = fs::exists(dir / "status.txt") ? bytes("status.txt") : "";
        const size_t at = line.find(" spp=");
        return at == std::string::npos ? 0 : std::atoi(line.c_str() + at + 5);
    };
    for (int i = 0; i < 2400 && spp() < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ASSERT_GE(spp(), 3);
    // Rank 1, found by its environment among the processes running this scratch folder's scene.
    pid_t rank1 = 0;
    for (const auto& entry : fs::directory_iterator("/proc")) {
        const std::string name = entry.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        std::string environ = test::read_file(entry.path() / "environ");
        std::replace(environ.begin(), environ.end(), '\0', '\n');
        if (environ.find("\nOMPI_COMM_WORLD_RANK=1\n") != std::string::npos &&
            environ.find(dir.string()) != std::string::npos)
            rank1 = pid_t(std::stoi(name));
    }
    ASSERT_GT(rank1, 0);
    ASSERT_EQ(::kill(rank1, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(launcher, &status, 0), launcher);  // the job's own --timeout would end a hang
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    const std::string err = bytes("killed.err");
    EXPECT_NE(err.find("error: the MPI job is ending (mpirun is ending it: a rank died"), std::string::npos) << err;
    EXPECT_EQ(err.find("did not finish within"), std::string::npos) << err;
}

// A bad scene beside a good one: one error line, a non-zero exit from every rank (no hang),
// the good scene written as without MPI.
TEST_F(Mpi, BadSceneIsOneErrorLineAndEveryRankExitsNonZero) {
    write("bad.json", "{\"cameras\": [");
    scene(1, 16, "good.json", "good.ppm");
    ASSERT_EQ(here(keithray() + "render -q good.json").status, 0);
    fs::rename(dir / "good.ppm", dir / "single.ppm");
    const test::CommandResult r = here(mpirun(3) + "render -q bad.json good.json");
    EXPECT_EQ(r.status, 1) << r.err;
    size_t errors = 0;
    for (size_t at = r.err.find("error: "); at != std::string::npos; at = r.err.find("error: ", at + 1)) ++errors;
    EXPECT_EQ(errors, 1u) << r.err;
    EXPECT_NE(r.err.find("error: bad.json: malformed JSON"), std::string::npos) << r.err;
    EXPECT_EQ(bytes("good.ppm"), bytes("single.ppm"));
}

// A rank killed mid-render: the job ends non-zero, mpirun names the cause, no image is
// written, and the last checkpoint resumes (at another rank count) to the uninterrupted image.
TEST_F(Mpi, RankKilledLeavesNoImageAndAResumableCheckpoint) {
    const std::string s = scene(6, 48, "scene.json");
    const std::string common = "render " + s + " --spp 3000 -q ";
    ASSERT_EQ(here(keithray() + common + "--threads 2 -o whole.ppm").status, 0);

    const fs::path checkpoint = dir / "r.ckpt";
    const pid_t launcher = ::fork();
    ASSERT_GE(launcher, 0);
    if (launcher == 0) {
        // mpirun itself (exec'd, so its ranks are this child's children).
        const std::string cmd = "cd '" + dir.string() + "' && exec " + mpirun(2).substr(mpirun(2).find('\'')) + common +
                                "-o cut.ppm --checkpoint r.ckpt --every 0 2>killed.err >killed.out";
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    for (int i = 0; i < 60000 && !fs::exists(checkpoint); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(fs::exists(checkpoint));
    // One rank, by its parent (mpirun): the last child listed.
    const test::CommandResult killed =
        test::run_command("kill -9 $(pgrep -P " + std::to_string(launcher) + " keithray | tail -1)", dir);
    EXPECT_EQ(killed.status, 0) << killed.err;
    int status = 0;
    ::waitpid(launcher, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    const std::string err = bytes("killed.err");
    EXPECT_NE(err.find("exited on signal 9"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir / "cut.ppm"));
    EXPECT_FALSE(fs::exists(dir / "cut-depth.ppm"));

    const test::CommandResult resumed = here(mpirun(3) + common + "-o cut.ppm --resume r.ckpt");
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_EQ(bytes("cut.ppm"), bytes("whole.ppm"));
    EXPECT_EQ(bytes("cut-depth.ppm"), bytes("whole-depth.ppm"));
}

// --time: the ranks agree after every pass, so they stop after the same one (a rank that
// went on alone would wait for the others in the next exchange until the timeout).
TEST_F(Mpi, TimeStopsEveryRankAfterTheSamePass) {
    scene(6, 32, "scene.json");
    const test::CommandResult r = here(mpirun(3) + "render scene.json --time 0.5 --spp 1000000 -q -o t.ppm");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("stopped by --time"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(dir / "t.ppm"));
}
