// Issue 47 C: the viewer's files as users expect them, at the model level (viewer/file_browser.h):
// the folder browser's listing, filter and navigation, what its Return does, the settings
// file (recent files, UI scale) with bad content ignored, a drop's actions, and the
// platform's chooser run as a child process (a stand-in zenity script on PATH).
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scene/scene_list.h"
#include "test_util.h"
#include "viewer/file_browser.h"
#include "viewer/save_dialog.h"

namespace fs = std::filesystem;
using namespace kr::viewer;

namespace {

class ViewerFiles : public kr::test::ScratchDirTest {
protected:
    void SetUp() override {
        ScratchDirTest::SetUp();
        fs::create_directories(dir / "scenes" / "more");
        fs::create_directories(dir / "scenes" / ".hidden");
        for (const char* f : {"scenes/b.json", "scenes/a.json", "scenes/notes.txt", "scenes/ref.PNG", "scenes/ref.exr",
                              "scenes/.dot.json", "scenes/more/c.json"})
            write(f, "{}");
    }
    static std::vector<std::string> names(const FileBrowser& b) {
        std::vector<std::string> out;
        for (const BrowserEntry& e : b.entries()) out.push_back(e.name + (e.folder ? "/" : ""));
        return out;
    }
};

// Restores an environment variable after a test that set it.
struct EnvVar {
    std::string name;
    std::optional<std::string> old;
    EnvVar(std::string n, const std::optional<std::string>& value) : name(std::move(n)) {
        if (const char* v = std::getenv(name.c_str())) old = v;
        if (value) ::setenv(name.c_str(), value->c_str(), 1);
        else ::unsetenv(name.c_str());
    }
    ~EnvVar() {
        if (old) ::setenv(name.c_str(), old->c_str(), 1);
        else ::unsetenv(name.c_str());
    }
};

}  // namespace

TEST_F(ViewerFiles, BrowserListsFoldersFirstThenTheFilesTheFilterPasses) {
    FileBrowser scenes(FilePurpose::open_scene, dir / "scenes");
    EXPECT_EQ(names(scenes), (std::vector<std::string>{"more/", "a.json", "b.json"}));
    EXPECT_TRUE(scenes.error().empty());
    FileBrowser images(FilePurpose::open_image, dir / "scenes");
    EXPECT_EQ(names(images), (std::vector<std::string>{"more/", "ref.PNG", "ref.exr"}));
    // "all files" lifts the filter (hidden names stay hidden).
    images.set_show_all(true);
    EXPECT_EQ(names(images), (std::vector<std::string>{"more/", "a.json", "b.json", "notes.txt", "ref.PNG", "ref.exr"}));
    EXPECT_TRUE(matches_filter("x.JSON", FilePurpose::save_scene));
    EXPECT_FALSE(matches_filter("x.json.bak", FilePurpose::open_scene));
    EXPECT_TRUE(matches_filter("x.pfm", FilePurpose::save_image));
}

TEST_F(ViewerFiles, BrowserEntersFoldersGoesUpAndReturnTakesAFolderOrAFile) {
    FileBrowser b(FilePurpose::open_scene, dir / "scenes");
    // Return on a folder's name enters it and clears the field.
    b.name = "more";
    EXPECT_FALSE(b.accept());
    EXPECT_EQ(b.folder(), fs::weakly_canonical(dir / "scenes" / "more"));
    EXPECT_EQ(b.name, "");
    EXPECT_EQ(names(b), (std::vector<std::string>{"c.json"}));
    b.up();
    EXPECT_EQ(b.folder(), fs::weakly_canonical(dir / "scenes"));
    b.name = "more/../a.json";  // a relative path
    auto chosen = b.accept();
    ASSERT_TRUE(chosen) << b.error();
    EXPECT_EQ(fs::weakly_canonical(*chosen), fs::weakly_canonical(dir / "scenes" / "a.json"));
    b.name = (dir / "scenes" / "more" / "c.json").string();  // an absolute one
    ASSERT_TRUE(b.accept()) << b.error();
    // What does not fit: one line naming the file, and nothing chosen.
    b.name = "missing.json";
    EXPECT_FALSE(b.accept());
    EXPECT_NE(b.error().find("missing.json\": no such file"), std::string::npos) << b.error();
    b.name = "notes.txt";
    EXPECT_FALSE(b.accept());
    EXPECT_NE(b.error().find("expected one of scenes (*.json)"), std::string::npos) << b.error();
    EXPECT_EQ(b.error().find('\n'), std::string::npos);
    b.name = "";
    EXPECT_FALSE(b.accept());
    EXPECT_FALSE(b.error().empty());
    // A folder that cannot be entered keeps the one shown.
    const fs::path before = b.folder();
    EXPECT_FALSE(b.go(dir / "scenes" / "a.json"));
    EXPECT_EQ(b.folder(), before);
    EXPECT_NE(b.error().find("not a folder"), std::string::npos);
    // Up from the root stays there.
    FileBrowser root(FilePurpose::open_scene, "/");
    root.up();
    EXPECT_EQ(root.folder(), fs::path("/"));
    // A start folder that is gone: the current folder, saying why.
    FileBrowser gone(FilePurpose::open_scene, dir / "gone");
    EXPECT_EQ(gone.folder(), fs::current_path());
    EXPECT_NE(gone.error().find("gone"), std::string::npos);
}

TEST_F(ViewerFiles, SaveTakesANameInAFolderAndGivesItTheFiltersExtension) {
    FileBrowser b(FilePurpose::save_scene, dir / "scenes", "copy");
    auto p = b.accept();
    ASSERT_TRUE(p) << b.error();
    EXPECT_EQ(*p, (dir / "scenes" / "copy.json").lexically_normal());
    b.name = "a.json";  // an existing file: chosen (the window's overwrite question asks)
    EXPECT_TRUE(b.accept());
    b.name = "nowhere/x.json";
    EXPECT_FALSE(b.accept());
    EXPECT_NE(b.error().find("no such folder"), std::string::npos) << b.error();
    b.name = "x.txt";
    EXPECT_FALSE(b.accept());
    FileBrowser image(FilePurpose::save_image, dir / "scenes", "shot");
    p = image.accept(".exr");
    ASSERT_TRUE(p) << image.error();
    EXPECT_EQ(p->filename(), "shot.exr");
    image.name = "shot.json";
    EXPECT_FALSE(image.accept());
}

TEST_F(ViewerFiles, SettingsFileKeepsRecentFilesBoundedAndTheScale) {
    const fs::path file = dir / "config" / "keithray" / kSettingsFileName;
    // No file yet: empty, no problem.
    LoadedSettings none = read_settings_file(file);
    EXPECT_EQ(none.settings, ViewerSettingsFile{});
    EXPECT_TRUE(none.problem.empty());
    ViewerSettingsFile s;
    for (int i = 0; i < 14; ++i) note_recent(s.scenes, dir / ("s" + std::to_string(i) + ".json"));
    note_recent(s.scenes, dir / "sub" / ".." / "s12.json");  // again, spelled otherwise: moves first, once
    ASSERT_EQ(s.scenes.size(), ViewerSettingsFile::kMaxRecent);
    EXPECT_EQ(s.scenes[0], dir / "s12.json");
    EXPECT_EQ(s.scenes[1], dir / "s13.json");
    EXPECT_EQ(std::count(s.scenes.begin(), s.scenes.end(), dir / "s12.json"), 1);
    note_recent(s.images, dir / "ref.png");
    s.ui_scale = 1.25;
    write_settings_file(file, s);  // makes its folder
    const LoadedSettings back = read_settings_file(file);
    EXPECT_TRUE(back.problem.empty()) << back.problem;
    EXPECT_EQ(back.settings, s);
    // Written atomically: nothing else is left in the folder.
    size_t count = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(file.parent_path())) ++count;
    EXPECT_EQ(count, 1u);
}

TEST_F(ViewerFiles, BadSettingsContentIsIgnoredWithAMessageNamingTheFile) {
    const fs::path file = dir / kSettingsFileName;
    auto problem_of = [&](const std::string& text) {
        write(kSettingsFileName, text);
        return read_settings_file(file);
    };
    for (const std::string bad : {"not json", "[1, 2]", "", "\x01\x02"}) {
        const LoadedSettings r = problem_of(bad);
        EXPECT_EQ(r.settings, ViewerSettingsFile{});
        EXPECT_NE(r.problem.find(file.string()), std::string::npos) << r.problem;
        EXPECT_NE(r.problem.find("ignored"), std::string::npos) << r.problem;
        EXPECT_EQ(r.problem.find('\n'), std::string::npos);
    }
    // The good parts of a partly bad file are kept.
    const LoadedSettings partly =
        problem_of(R"({"recent_scenes": ["/a.json", 7, "relative.json", "/a.json", "/b.json"], "recent_images": "x",
                      "ui_scale": 40})");
    EXPECT_EQ(partly.settings.scenes, (std::vector<fs::path>{"/a.json", "/b.json"}));
    EXPECT_TRUE(partly.settings.images.empty());
    EXPECT_FALSE(partly.settings.ui_scale);
    EXPECT_FALSE(partly.problem.empty());
    // More entries than kept: the newest only.
    std::string many = R"({"recent_images": [)";
    for (int i = 0; i < 30; ++i) many += (i ? ",\"/i" : "\"/i") + std::to_string(i) + ".png\"";
    const LoadedSettings bounded = problem_of(many + "]}");
    EXPECT_EQ(bounded.settings.images.size(), ViewerSettingsFile::kMaxRecent);
    EXPECT_EQ(bounded.settings.images[0], fs::path("/i0.png"));
    // A huge file is not read at all.
    write(kSettingsFileName, std::string(300 * 1024, ' '));
    EXPECT_NE(read_settings_file(file).problem.find("larger than"), std::string::npos);
    // A folder where the file should be.
    fs::remove(file);
    fs::create_directories(file);
    EXPECT_NE(read_settings_file(file).problem.find("not a regular file"), std::string::npos);
}

TEST_F(ViewerFiles, ConfigDirFollowsXdgConfigHomeThenHome) {
    {
        EnvVar xdg("XDG_CONFIG_HOME", (dir / "xdg").string());
        EXPECT_EQ(config_dir(), dir / "xdg" / "keithray");
    }
    {
        EnvVar xdg("XDG_CONFIG_HOME", std::string("relative"));  // invalid by the spec: ignored
        EnvVar home("HOME", (dir / "home").string());
        EXPECT_EQ(config_dir(), dir / "home" / ".config" / "keithray");
    }
    {
        EnvVar xdg("XDG_CONFIG_HOME", std::nullopt);
        EnvVar home("HOME", std::nullopt);
        EXPECT_TRUE(config_dir().empty());
    }
}

TEST_F(ViewerFiles, ADropOpensOneSceneAndOneImageAndRefusesTheRestByName) {
    const auto actions = plan_drop({dir / "scenes" / "a.json", dir / "scenes" / "notes.txt", dir / "scenes" / "ref.PNG",
                                    dir / "scenes" / "b.json", dir / "scenes", dir / "scenes" / "ref.exr"});
    ASSERT_EQ(actions.size(), 6u);
    EXPECT_EQ(actions[0].kind, DropAction::scene);
    EXPECT_EQ(actions[1].kind, DropAction::refused);
    EXPECT_NE(actions[1].error.find("notes.txt\": not a scene (*.json) or an image (*.ppm *.png *.exr *.pfm)"),
              std::string::npos)
        << actions[1].error;
    EXPECT_EQ(actions[2].kind, DropAction::image);
    EXPECT_EQ(actions[3].kind, DropAction::refused);  // a second scene
    EXPECT_NE(actions[3].error.find("b.json\": one scene opens at a time"), std::string::npos) << actions[3].error;
    EXPECT_EQ(actions[4].kind, DropAction::refused);  // a folder
    EXPECT_NE(actions[4].error.find("a folder"), std::string::npos);
    EXPECT_EQ(actions[5].kind, DropAction::refused);  // a second image
    for (const DropAction& a : actions) EXPECT_EQ(a.error.find('\n'), std::string::npos);
    // A file that is not there, and one that is not a regular file (a FIFO would block).
    ASSERT_EQ(::mkfifo((dir / "pipe.json").c_str(), 0600), 0);
    const auto odd = plan_drop({dir / "gone.png", dir / "pipe.json"});
    EXPECT_NE(odd[0].error.find("gone.png\": no such file"), std::string::npos) << odd[0].error;
    EXPECT_NE(odd[1].error.find("pipe.json\": not a regular file"), std::string::npos) << odd[1].error;
}

// A bundled example opened by any path (browser, recent, drop) is read-only to Save: Save
// asks where (save_dialog.h), whatever way it was named.
TEST_F(ViewerFiles, ABundledExampleIsReadOnlyHoweverItIsNamed) {
    const auto examples = kr::example_scenes();
    ASSERT_FALSE(examples.empty());
    const fs::path example = examples.front();
    FileBrowser b(FilePurpose::open_scene, example.parent_path());
    b.name = example.filename().string();
    const auto chosen = b.accept();
    ASSERT_TRUE(chosen) << b.error();
    EXPECT_TRUE(scene_file_read_only(*chosen, kr::data_dir()));
    ViewerSettingsFile s;
    note_recent(s.scenes, *chosen);
    EXPECT_TRUE(scene_file_read_only(s.scenes.front(), kr::data_dir()));
    const auto drop = plan_drop({example.parent_path() / ".." / "examples" / example.filename()});
    ASSERT_EQ(drop[0].kind, DropAction::scene);
    EXPECT_TRUE(scene_file_read_only(drop[0].file, kr::data_dir()));
}

// The platform's chooser: zenity's command line, and a stand-in on PATH run as a child:
// its answer, its Cancel and its failure, read without blocking.
TEST_F(ViewerFiles, PlatformChooserRunsAsAChildAndItsAnswerIsTheFile) {
    const auto args = zenity_arguments(FilePurpose::save_scene, dir, "x.json");
    ASSERT_GE(args.size(), 4u);
    EXPECT_EQ(args[0], "zenity");
    EXPECT_NE(std::find(args.begin(), args.end(), "--save"), args.end());
    EXPECT_NE(std::find(args.begin(), args.end(), "--filename=" + (dir / "x.json").string()), args.end());
    EXPECT_NE(std::find(args.begin(), args.end(), "--file-filter=Scenes | *.json"), args.end());
    const auto open_args = zenity_arguments(FilePurpose::open_image, dir, "");
    EXPECT_EQ(std::find(open_args.begin(), open_args.end(), "--save"), open_args.end());
    EXPECT_NE(std::find(open_args.begin(), open_args.end(), "--filename=" + dir.string() + "/"), open_args.end());

    // A stand-in zenity: answers what its first argument's file says, exits with the second's status.
    fs::create_directories(dir / "bin");
    write("bin/zenity", "#!/bin/sh\ncat \"$KR_ANSWER\"\nexit \"$(cat \"$KR_STATUS\")\"\n");
    fs::permissions(dir / "bin" / "zenity", fs::perms::owner_all);
    EnvVar path("PATH", (dir / "bin").string() + ":" + std::getenv("PATH"));
    EnvVar answer("KR_ANSWER", (dir / "answer").string());
    EnvVar status("KR_STATUS", (dir / "status").string());
    {
        EnvVar choice("KEITHRAY_FILE_CHOOSER", std::nullopt);
        EXPECT_EQ(native_chooser(), "zenity");
        EnvVar builtin("KEITHRAY_FILE_CHOOSER", std::string("builtin"));
        EXPECT_EQ(native_chooser(), "");
    }
    EXPECT_EQ(find_on_path("zenity"), dir / "bin" / "zenity");
    EXPECT_TRUE(find_on_path("keithray-no-such-program").empty());

    auto run = [&](const std::string& out, const std::string& code) {
        write("answer", out);
        write("status", code);
        ChildChooser c;
        EXPECT_TRUE(c.start({"zenity", "--file-selection"}, FilePurpose::open_scene)) << c.error;
        EXPECT_TRUE(c.running());
        return c.wait();
    };
    ChildChooser::Result r = run((dir / "a b.json").string() + "\n", "0");
    ASSERT_TRUE(r.file);
    EXPECT_EQ(*r.file, dir / "a b.json");
    EXPECT_TRUE(r.error.empty());
    r = run("", "1");  // Cancel
    EXPECT_FALSE(r.file);
    EXPECT_TRUE(r.error.empty());
    r = run("", "5");
    EXPECT_FALSE(r.file);
    EXPECT_NE(r.error.find("exit status 5"), std::string::npos) << r.error;
    // poll() never blocks: it answers once the child has ended, then nothing more.
    write("answer", "/x.json\n");
    write("status", "0");
    ChildChooser c;
    ASSERT_TRUE(c.start({"zenity"}, FilePurpose::open_scene));
    std::optional<ChildChooser::Result> polled;
    while (!(polled = c.poll())) ::usleep(1000);
    ASSERT_TRUE(polled->file);
    EXPECT_EQ(*polled->file, fs::path("/x.json"));
    EXPECT_FALSE(c.running());
    EXPECT_FALSE(c.poll());
    // A program that is not there: cannot start, saying so.
    ChildChooser missing;
    EXPECT_FALSE(missing.start({"keithray-no-such-program"}, FilePurpose::open_scene));
    EXPECT_NE(missing.error.find("cannot run keithray-no-such-program"), std::string::npos) << missing.error;
}
