// keithray's man page and bash completion, made from the same texts `--help` prints (each
// command's help text, the shared flags' table of render/options.h) and the name tables
// its parsers read values from, so they cannot drift from the program. CMake runs
// `keithray --help-man` and `keithray --completion bash` at build time and installs what
// they print (docs/install.md).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace kr {

// One command as its help text describes it.
struct CommandHelp {
    std::string name;        // "render"
    std::string summary;     // one line for the man page's list of commands
    std::string help;        // what `keithray NAME --help` prints
    std::string positional;  // what its arguments are: "scene", "image" or "" (none)
    // Flags whose value is one of a name table's names, beyond the shared flags: {flag, names}.
    std::vector<std::pair<std::string, std::vector<std::string>>> names;
};

// An option line of a help text: "  -q, --quiet    no progress bar" has the flags {"-q",
// "--quiet"}, no value, and the text; continuation lines are joined to its text.
struct HelpOption {
    std::vector<std::string> flags;
    std::string value;  // the value's placeholder ("N", "OUT.ppm", "[NAME]"), empty for none
    std::string text;
};
std::vector<HelpOption> help_options(const std::string& help);

// Every flag a help text names: its option lines' and its usage lines' ("[--runs N]").
std::vector<std::string> help_flags(const std::string& help, const std::string& command);

// keithray(1) in man(7) roff: NAME, SYNOPSIS, a section per command from its help text, the
// files and the exit status.
std::string man_page(const std::string& version, const std::string& synopsis, const std::string& description,
                     const std::vector<CommandHelp>& commands);

// A bash completion script (`complete -F _keithray keithray`): the commands, each one's flags,
// the names a name flag takes, file names where a flag or argument is a file.
std::string bash_completion(const std::vector<CommandHelp>& commands, const std::vector<std::string>& top_flags);

}  // namespace kr
