// keithray under mpirun (issue 26; app/cluster.h): the bytes of the render without MPI at 1,
// 2 and 3 ranks for every integrator, estimator and allocation and the noise rule; a bad
// scene ends every rank with one error line; a rank killed mid-render ends the job non-zero
// with no image and a checkpoint that resumes to the uninterrupted image. Every run is under
// `timeout`: a hang fails the test instead of the suite.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

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
    // Scene `n` of the brief at size x size pixels, written to the scratch folder.
    std::string scene(int n, int size, const std::string& name, const std::string& output = "out.ppm") {
        Scene s = test::brief_scene(n, size);
        s.renderer.output = (dir / output).string();  // beside the scene file
        save_scene_json(s, dir / name);
        return name;
    }
    std::string bytes(const std::string& name) { return test::read_file(dir / name); }
};

}  // namespace

TEST_F(Mpi, SameBytesAtOneTwoAndThreeRanks) {
    const std::string wrt = scene(1, 32, "wrt.json"), pt = scene(6, 32, "pt.json");
    struct Case {
        const char* name;
        std::string args, output;
    };
    for (const Case& c : {Case{"wrt uniform", wrt + " --spp 6 --allocation uniform", "a.ppm"},
                          Case{"pt uniform", pt + " --spp 10 --allocation uniform", "a.ppm"},
                          Case{"pt adaptive", pt + " --spp 24", "a.ppm"},
                          Case{"pt noise", pt + " --noise 0.03 --spp 400", "a.ppm"},
                          Case{"pt stratified, every layer", pt + " --spp 9 --estimator stratified", "a.exr"}}) {
        SCOPED_TRACE(c.name);
        const test::CommandResult single = here(keithray() + "render -q --threads 2 " + c.args + " -o single-" + c.output);
        ASSERT_EQ(single.status, 0) << single.err;
        // The noise rule stops it, after its mask has steered passes (from pass 16 on).
        if (c.args.find("--noise") != std::string::npos) {
            const size_t at = single.err.find("stopped by --noise after ");
            ASSERT_NE(at, std::string::npos) << single.err;
            EXPECT_GT(std::stoi(single.err.substr(at + 25)), 16) << single.err;
        }
        for (int ranks : {1, 2, 3}) {
            SCOPED_TRACE(ranks);
            const std::string out = std::to_string(ranks) + "-" + c.output;
            const test::CommandResult r = here(mpirun(ranks) + "render -q " + c.args + " -o " + out);
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(bytes(out), bytes("single-" + c.output));
            if (c.output.ends_with(".ppm")) EXPECT_EQ(bytes(std::to_string(ranks) + "-a-depth.ppm"), bytes("single-a-depth.ppm"));
            // Rank 0 prints the summary once, with each rank's busy time.
            EXPECT_NE(r.out.find(std::to_string(ranks) + " ranks: busy s"), std::string::npos) << r.out;
        }
    }
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
