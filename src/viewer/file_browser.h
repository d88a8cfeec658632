// The viewer's file dialogs without their widgets (ui_file_dialog.cpp draws them): a folder
// browser (listing, filter, navigation, what the name field's Return does), the platform's
// file chooser run as a child process (zenity, where it is on PATH), the recent files and the
// UI scale kept in a small settings file, and what a file dropped on the window does. GL-free.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace kr::viewer {

// What a dialog is for: it sets the filter (scenes: *.json; images: the formats of
// core/image_formats.h) and whether the name must name an existing file.
enum class FilePurpose { open_scene, open_image, save_scene, save_image };
bool purpose_saves(FilePurpose purpose);
const char* purpose_title(FilePurpose purpose);  // "Open scene", "Open image B", ...
const char* purpose_word(FilePurpose purpose);   // the status file's: "open-scene", ...

// Whether `file`'s name fits `purpose`'s filter (extension in any case).
bool matches_filter(const std::filesystem::path& file, FilePurpose purpose);
// The filter in words, for messages and the dialog: "scenes (*.json)".
std::string filter_words(FilePurpose purpose);

// One row of the browser's list: a folder (entered on Return or a double click) or a file.
struct BrowserEntry {
    std::string name;
    bool folder = false;
    bool operator==(const BrowserEntry&) const = default;
};

// A folder browser: the folder's subfolders (sorted, first) then its files that pass the
// filter (sorted); names starting with '.' are hidden. A folder that cannot be read lists
// nothing and says why (`error`).
class FileBrowser {
public:
    FileBrowser(FilePurpose purpose, const std::filesystem::path& folder, std::string name = {});

    FilePurpose purpose() const { return purpose_; }
    const std::filesystem::path& folder() const { return folder_; }
    const std::vector<BrowserEntry>& entries() const { return entries_; }
    const std::string& error() const { return error_; }
    bool show_all() const { return show_all_; }

    // Lists the folder again (after a change outside, or of the filter).
    void refresh();
    void set_show_all(bool all);
    // Into `folder` (absolute, or relative to the one shown); false (and `error`) when it is
    // not a readable folder, the folder shown stays.
    bool go(const std::filesystem::path& folder);
    // To the parent folder (the root stays the root).
    void up();

    // The name field (a file name, a path relative to the folder, an absolute path, or a
    // folder, ~ for the home folder).
    std::string name;

    // The name field's Return (and the Open / Save button): a folder is entered (nullopt;
    // the field cleared); otherwise the file it names, when it fits: to open, an existing
    // regular file that passes the filter; to save, a name in an existing folder, given the
    // filter's extension when it has none (a scene: .json; an image: `default_extension`).
    // nullopt and `error` (one line naming the file) when it does not fit.
    std::optional<std::filesystem::path> accept(const std::string& default_extension = ".png");

private:
    std::filesystem::path resolve(const std::string& text) const;

    FilePurpose purpose_;
    std::filesystem::path folder_;
    std::vector<BrowserEntry> entries_;
    std::string error_;
    bool show_all_ = false;
};

// ---- The settings file: recent files and the UI scale ----

// Where the viewer keeps its settings: $XDG_CONFIG_HOME/keithray when that is an absolute
// path, else $HOME/.config/keithray; empty when neither is set.
std::filesystem::path config_dir();
inline constexpr const char* kSettingsFileName = "viewer.json";

// What the settings file holds: the scenes and the images (image B) opened last, newest
// first, at most kMaxRecent of each, as absolute paths; the UI scale the user set (none:
// follow the monitor alone).
struct ViewerSettingsFile {
    static constexpr size_t kMaxRecent = 10;
    static constexpr double kMinUiScale = 0.5, kMaxUiScale = 3.0;
    std::vector<std::filesystem::path> scenes, images;
    std::optional<double> ui_scale;
    bool operator==(const ViewerSettingsFile&) const = default;
};

// Puts `file` (made absolute, normalised) first in `list`, once, keeping at most kMaxRecent.
void note_recent(std::vector<std::filesystem::path>& list, const std::filesystem::path& file);

// Reads the settings file. A missing file is an empty one; content that is not such a file
// (not JSON, wrong types, entries not paths, a scale out of range) is left out, and `problem`
// says so in one line naming the file. Nothing is ever thrown.
struct LoadedSettings {
    ViewerSettingsFile settings;
    std::string problem;
};
LoadedSettings read_settings_file(const std::filesystem::path& file);
// Writes it atomically (core/file_write.h), making its folder; throws std::exception with
// the reason when it cannot.
void write_settings_file(const std::filesystem::path& file, const ViewerSettingsFile& settings);

// ---- Dropped files ----

// What a file dropped on the window does: a scene (*.json) opens as from Open (asking first
// with unsaved edits), an image becomes image B as the reference; anything else is refused
// with a one-line error naming the file (so are a folder, a missing file and one that is
// not a regular file: a FIFO would block the window on its first read).
struct DropAction {
    enum Kind { scene, image, refused };
    Kind kind = refused;
    std::filesystem::path file;
    std::string error;  // refused: why
};
// The actions of one drop, in order: at most one scene and one image act (the first of
// each); the others are refused, saying so.
std::vector<DropAction> plan_drop(const std::vector<std::filesystem::path>& files);

// ---- The platform's file chooser ----

// The chooser to use: KEITHRAY_FILE_CHOOSER=builtin (the ImGui browser), =zenity, or
// unset: zenity where it is on PATH, else the ImGui browser. Empty: the ImGui browser.
std::string native_chooser();
// Where `program` is on PATH (empty: nowhere).
std::filesystem::path find_on_path(const std::string& program);
// zenity's command line for `purpose`, starting in `folder` with `name` offered.
std::vector<std::string> zenity_arguments(FilePurpose purpose, const std::filesystem::path& folder,
                                          const std::string& name);

// A chooser run as a child process, its standard output read without blocking the window:
// exit 0 and a line is the chosen file, exit 1 is Cancel, anything else an error.
class ChildChooser {
public:
    ChildChooser() = default;
    ChildChooser(const ChildChooser&) = delete;
    ChildChooser& operator=(const ChildChooser&) = delete;
    ~ChildChooser();

    // Starts `argv` (argv[0] looked up on PATH); false (and `error`) when it cannot start.
    bool start(const std::vector<std::string>& argv, FilePurpose purpose);
    bool running() const { return pid_ > 0; }
    FilePurpose purpose() const { return purpose_; }

    struct Result {
        std::optional<std::filesystem::path> file;  // none: cancelled, or an error
        std::string error;
    };
    // Once the child has ended, its result (once); nullopt while it runs.
    std::optional<Result> poll();
    // Waits for the child to end (tests; the window polls instead).
    Result wait();
    std::string error;

private:
    std::optional<Result> finish(int status);
    pid_t pid_ = -1;
    int out_ = -1;
    std::string output_;
    FilePurpose purpose_ = FilePurpose::open_scene;
};

}  // namespace kr::viewer
