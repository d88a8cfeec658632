// Where keithray finds its bundled files (core/data_dir.h) and what it never writes: the
// lookup from the executable's folder in an install tree and in a build tree, the outputs of
// bundled scenes moved out of the install tree, the viewer's read-only scenes. The installed
// program itself is run by tests/install_check.sh (Install.*). Likewise its modules
// (core/module.h): found beside bin/ in an install, through the marker in a build tree, and a
// missing one refused in one line that names its file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/data_dir.h"
#include "core/module.h"
#include "render/accel.h"
#include "scene/scene_list.h"
#include "viewer/save_dialog.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

class DataDirLookup : public test::ScratchDirTest {};

TEST_F(DataDirLookup, ModulesInTheInstallTreeWinOverTheBuildMarker) {
    const fs::path installed = (dir / "prefix/bin" / installed_modules_from_bin()).lexically_normal();
    fs::create_directories(installed);
    fs::create_directories(dir / "prefix/bin");
    fs::create_directories(dir / "modules");
    write("modules/keithray_viewer.so", "");
    write("prefix/bin/keithray-modules.path", (dir / "modules").string() + "\n");
    // Only the build's: found through the marker.
    EXPECT_EQ(find_module(dir / "prefix/bin", "viewer"), dir / "modules/keithray_viewer.so");
    std::ofstream(installed / "keithray_viewer.so").put('x');
    EXPECT_EQ(find_module(dir / "prefix/bin", "viewer"), installed / "keithray_viewer.so");
    // Neither: the install's place, for the message.
    EXPECT_EQ(find_module(dir / "prefix/bin", "mpi"), installed / "keithray_mpi.so");
    EXPECT_EQ(find_module(dir / "elsewhere", "mpi"),
              (dir / "elsewhere" / installed_modules_from_bin() / "keithray_mpi.so").lexically_normal());
}

TEST(Modules, AMissingModuleIsRefusedInOneLineNamingItsFile) {
    try {
        load_module("no_such_part", nullptr, "the part", "libnothing");
        FAIL() << "a missing module loaded";
    } catch (const std::runtime_error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("the part: its module "), std::string::npos) << message;
        EXPECT_NE(message.find("keithray_no_such_part.so is missing"), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST(Modules, TheTestBinaryLoadsTheBuildsEmbreeModule) {
    if (!embree_available()) GTEST_SKIP() << "this build has no Embree";
    const EmbreeModule& module = embree_module();
    EXPECT_NE(module.build, nullptr);
    EXPECT_STRNE(module.embree_version, "");
    EXPECT_EQ(&module, &embree_module());  // loaded once
}

TEST_F(DataDirLookup, InstallTreeBesideBinWinsOverTheBuildMarker) {
    fs::create_directories(dir / "prefix/bin");
    fs::create_directories(dir / "prefix/share/keithray/scenes");
    fs::create_directories(dir / "res/scenes");
    write("prefix/bin/keithray-res.path", (dir / "res").string() + "\n");
    const auto found = find_data_dir(dir / "prefix/bin");
    ASSERT_TRUE(found);
    EXPECT_TRUE(found->installed);
    EXPECT_EQ(found->path, (dir / "prefix/bin" / installed_data_from_bin()).lexically_normal());
    EXPECT_EQ(found->path, dir / "prefix/share/keithray");
}

TEST_F(DataDirLookup, BuildTreeThroughItsMarkerOnly) {
    fs::create_directories(dir / "build");
    fs::create_directories(dir / "res/scenes");
    EXPECT_FALSE(find_data_dir(dir / "build"));  // no marker: nothing, never the working folder's res/
    write("build/keithray-res.path", (dir / "res").string() + "\n");
    const auto found = find_data_dir(dir / "build");
    ASSERT_TRUE(found);
    EXPECT_FALSE(found->installed);
    EXPECT_EQ(found->path, dir / "res");
    // A marker naming a folder without scenes/ finds nothing.
    write("build/keithray-res.path", (dir / "nowhere").string());
    EXPECT_FALSE(find_data_dir(dir / "build"));
}

TEST(DataDir, TheTestBinaryFindsTheSourceTreesBundledScenes) {
    // CMake's marker beside the test binary names the source tree's res/.
    ASSERT_TRUE(data_dir());
    EXPECT_FALSE(data_dir()->installed);
    EXPECT_TRUE(fs::equivalent(data_dir()->path, KEITHRAY_RES_DIR));
    EXPECT_EQ(default_scenes().size(), 8u);
    EXPECT_GE(example_scenes().size(), 5u);
    EXPECT_TRUE(fs::equivalent(default_view_scene(), test::brief_scene_file(3)));
}

class InstalledScenes : public test::ScratchDirTest {
protected:
    DataDir data;
    Scene scene;
    void SetUp() override {
        test::ScratchDirTest::SetUp();
        data = {dir / "share/keithray", true};
        fs::create_directories(data.path / "scenes/examples");
        scene.source_file = data.path / "scenes/assignment_03.json";
        scene.renderer.output = "../output/assignment_03.ppm";
    }
};

TEST_F(InstalledScenes, OutputsInTheInstallTreeGoToTheCurrentFolder) {
    EXPECT_EQ(output_outside_install(scene, data), fs::path("output/assignment_03.ppm"));
    // An example writing beside itself, too.
    scene.source_file = data.path / "scenes/examples/denoise_dof.json";
    scene.renderer.output = "denoise_dof.ppm";
    EXPECT_EQ(output_outside_install(scene, data), fs::path("output/denoise_dof.ppm"));
    // Not installed (a build's res/), or an output outside the tree: the file's output stands.
    EXPECT_FALSE(output_outside_install(scene, DataDir{data.path, false}));
    EXPECT_FALSE(output_outside_install(scene, std::nullopt));
    scene.renderer.output = (dir / "elsewhere/x.png").string();
    EXPECT_FALSE(output_outside_install(scene, data));
    // A name that is no file's: the scene's name as .ppm.
    scene.renderer.output = "";
    EXPECT_EQ(output_in_current_folder(scene), fs::path("output/denoise_dof.ppm"));
}

TEST_F(InstalledScenes, TheViewerSavesAnInstalledSceneElsewhere) {
    write("share/keithray/scenes/assignment_03.json", "{}");
    write("mine.json", "{}");
    EXPECT_TRUE(viewer::scene_file_read_only(scene.source_file, data));
    EXPECT_FALSE(viewer::scene_file_read_only(dir / "mine.json", data));
    // A build's res/ too: the shipped scenes and examples are never saved over (issue 47 B6).
    EXPECT_TRUE(viewer::scene_file_read_only(scene.source_file, DataDir{data.path, false}));
    EXPECT_TRUE(viewer::scene_file_read_only(data.path / "scenes/examples/furnace.json", DataDir{data.path, false}));
    // Save asks with the current folder's NAME.json; a writable scene's default stays beside it.
    EXPECT_EQ(viewer::SavePaths::for_scene(scene, true).scene, "assignment_03.json");
    EXPECT_EQ(fs::path(viewer::SavePaths::for_scene(scene, false).scene),
              data.path / "scenes/assignment_03-edited.json");
}
