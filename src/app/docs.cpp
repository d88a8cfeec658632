#include "app/docs.h"

#include <algorithm>
#include <cctype>
#include <regex>
#include <sstream>

#include "render/options.h"

namespace kr {

namespace {

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

size_t indent_of(const std::string& line) {
    const size_t at = line.find_first_not_of(' ');
    return at == std::string::npos ? line.size() : at;
}

std::string trimmed(const std::string& s) {
    const size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
    return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

bool is_blank(const std::string& line) { return line.find_first_not_of(' ') == std::string::npos; }

// An option line: at most 4 columns in, starting with '-': its flags, then placeholders
// (words starting with a capital or '['), then after two or more spaces (or a word that is
// no placeholder) its text.
bool read_option_line(const std::string& line, HelpOption& option) {
    const size_t indent = indent_of(line);
    if (indent > 4 || indent >= line.size() || line[indent] != '-' || line.size() < indent + 2 ||
        !(std::isalpha(static_cast<unsigned char>(line[indent + 1])) || line[indent + 1] == '-'))
        return false;
    const std::string rest = line.substr(indent);
    const size_t gap = rest.find("  ");
    std::string term = gap == std::string::npos ? rest : rest.substr(0, gap);
    std::string text = gap == std::string::npos ? "" : trimmed(rest.substr(gap));
    option = {};
    std::istringstream words(term);
    std::vector<std::string> spill;
    for (std::string w; words >> w;) {
        if (!spill.empty()) spill.push_back(w);
        else if (option.value.empty() && w[0] == '-') {
            if (w.back() == ',') w.pop_back();
            // A flag is a name, or the line is text that starts with one ("--blur); NAME...").
            static const std::regex name(R"(--?[A-Za-z][A-Za-z0-9-]*)");
            if (!std::regex_match(w, name)) return false;
            option.flags.push_back(w);
        } else if (std::isupper(static_cast<unsigned char>(w[0])) || w[0] == '[')
            option.value += (option.value.empty() ? "" : " ") + w;
        else spill.push_back(w);
    }
    if (!spill.empty()) {
        std::string lead;
        for (const std::string& w : spill) lead += (lead.empty() ? "" : " ") + w;
        text = text.empty() ? lead : lead + " " + text;
    }
    option.text = text;
    return !option.flags.empty();
}

// man(7) text: backslashes and hyphens escaped, a control character at a line's start
// neutralised.
std::string roff_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '\\') out += "\\e";
        else if (c == '-') out += "\\-";
        else out += c;
    }
    if (!out.empty() && (out[0] == '.' || out[0] == '\'')) out = "\\&" + out;
    return out;
}

// A help text in roff: "Usage:" blocks verbatim, option lines as tagged paragraphs, a line
// ending in ':' alone as a bold heading, the rest as filled paragraphs.
std::string help_to_roff(const std::string& help) {
    std::string out;
    enum { none, paragraph, item, verbatim } state = none;
    size_t item_indent = 0;
    for (const std::string& line : lines_of(help)) {
        if (is_blank(line)) {
            if (state == verbatim) out += ".fi\n";
            state = none;
            continue;
        }
        HelpOption option;
        if (state == verbatim) {
            out += roff_escape(line) + "\n";
        } else if (line.rfind("Usage:", 0) == 0) {
            out += ".PP\n.nf\n" + roff_escape(line) + "\n";
            state = verbatim;
        } else if (read_option_line(line, option)) {
            std::string term;
            for (const std::string& f : option.flags) term += (term.empty() ? "" : ", ") + ("\\fB" + roff_escape(f) + "\\fR");
            if (!option.value.empty()) term += " \\fI" + roff_escape(option.value) + "\\fR";
            out += ".TP\n" + term + "\n";
            if (!option.text.empty()) out += roff_escape(option.text) + "\n";
            state = item;
            item_indent = indent_of(line);
        } else if (state == item && indent_of(line) > item_indent) {
            out += roff_escape(trimmed(line)) + "\n";
        } else if (indent_of(line) == 0 && line.back() == ':' && state != paragraph) {
            out += ".PP\n\\fB" + roff_escape(line) + "\\fR\n";
            state = none;
        } else {
            if (state != paragraph) out += ".PP\n";
            out += roff_escape(trimmed(line)) + "\n";
            state = paragraph;
        }
    }
    if (state == verbatim) out += ".fi\n";
    return out;
}

bool takes_file(const std::string& value) {
    static const std::regex file(R"(FILE|OUT|IMAGE|SCENE|\.json|\.ppm|\.png|\.exr|\.pfm|\.csv)");
    return std::regex_search(value, file);
}

std::string shell_words(const std::vector<std::string>& words) {
    std::string out;
    for (const std::string& w : words) out += (out.empty() ? "" : " ") + w;
    return out;
}

std::vector<std::string> split_names(const std::string& list) {
    std::vector<std::string> names;
    std::istringstream in(list);
    for (std::string w; in >> w;)
        if (w != "|") names.push_back(w);
    return names;
}

}  // namespace

std::vector<HelpOption> help_options(const std::string& help) {
    std::vector<HelpOption> options;
    bool in_item = false;
    size_t item_indent = 0;
    for (const std::string& line : lines_of(help)) {
        HelpOption option;
        if (is_blank(line)) in_item = false;
        else if (read_option_line(line, option)) {
            options.push_back(option);
            in_item = true;
            item_indent = indent_of(line);
        } else if (in_item && indent_of(line) > item_indent) options.back().text += " " + trimmed(line);
        else in_item = false;
    }
    return options;
}

std::vector<std::string> help_flags(const std::string& help, const std::string& command) {
    std::vector<std::string> flags;
    auto add = [&](const std::string& f) {
        if (std::find(flags.begin(), flags.end(), f) == flags.end()) flags.push_back(f);
    };
    for (const HelpOption& o : help_options(help))
        for (const std::string& f : o.flags) add(f);
    // The usage lines of this command ("keithray bench --stress N[,N...] [--accel LIST]") and
    // their continuations ("                 [--kernels ...]").
    static const std::regex flag(R"((^|[\s\[|])(--?[A-Za-z][A-Za-z0-9-]*))");
    bool usage = false;
    for (const std::string& line : lines_of(help)) {
        if (line.find("keithray " + command) != std::string::npos) usage = true;
        else if (!(usage && indent_of(line) > 0 && trimmed(line).rfind("[", 0) == 0)) usage = false;
        if (!usage) continue;
        for (std::sregex_iterator it(line.begin(), line.end(), flag), end; it != end; ++it) add((*it)[2].str());
    }
    return flags;
}

std::string man_page(const std::string& version, const std::string& synopsis, const std::string& description,
                     const std::vector<CommandHelp>& commands) {
    std::string out;
    out += ".\\\" keithray(1), generated by `keithray --help-man` from the help texts `keithray --help` prints.\n";
    out += ".TH KEITHRAY 1 \"\" \"keithray " + version + "\" \"User Commands\"\n";
    // No hyphenation, ragged right: flags and names stay whole and searchable.
    out += ".nh\n.ad l\n";
    out += ".SH NAME\nkeithray \\- a progressive ray tracer for sphere scenes\n";
    out += ".SH SYNOPSIS\n.nf\n";
    // The usage lines' commands, without their notes ("keithray psnr IMAGE REFERENCE").
    for (const std::string& line : lines_of(synopsis)) {
        const std::string command = trimmed(line);
        if (command.rfind("keithray ", 0) != 0) continue;
        std::string kept;  // up to the note: two spaces, or a word in lower case after the command's
        std::istringstream words(command.substr(0, command.find("  ")));
        int at = 0;
        for (std::string w; words >> w; ++at) {
            if (at >= 2 && std::islower(static_cast<unsigned char>(w[0]))) break;
            kept += (kept.empty() ? "" : " ") + w;
        }
        out += roff_escape(kept) + "\n";
    }
    out += ".fi\n";
    out += ".SH DESCRIPTION\n" + help_to_roff(description);
    out += ".PP\nThe commands:\n";
    for (const CommandHelp& c : commands) out += ".TP\n.B " + c.name + "\n" + roff_escape(c.summary) + "\n";
    out += ".TP\n\\fB\\-\\-version\\fR, \\fB\\-V\\fR\nthe version, the build type, the SIMD kernels this CPU "
           "runs, whether Embree, MPI and the viewer are built in, and where the bundled scenes are\n";
    out += ".TP\n\\fB\\-\\-help\\fR\nthe usage and render's options; \\fBkeithray\\fR \\fICOMMAND\\fR "
           "\\fB\\-\\-help\\fR each command's\n";
    for (const CommandHelp& c : commands) {
        std::string heading = "KEITHRAY " + c.name;
        for (char& ch : heading) ch = char(std::toupper(static_cast<unsigned char>(ch)));
        out += ".SH \"" + heading + "\"\n" + help_to_roff(c.help);
    }
    out += R"(.SH FILES
.TP
.I share/keithray/scenes/
the brief's eight scenes, which \fBrender\fR renders when no scene is given (into
\fIoutput/\fR under the current folder) and \fBview\fR opens (assignment_03.json) when none
is given; found beside the program: \fI../share/keithray\fR from its \fIbin/\fR folder
(\fI/usr/share/keithray\fR for the Debian package), or a build tree's \fIres/\fR
.TP
.I share/keithray/scenes/examples/
the example scenes of the viewer's Open list
.TP
.I share/keithray/references/
the brief's reference renders, the viewer's image B for the brief's scenes
.PP
A scene of the install tree is never written: its render goes to \fIoutput/\fR under the
current folder, and the viewer's Save asks where to save it.
.SH ENVIRONMENT
.TP
.B OMP_NUM_THREADS
worker threads (as \fB\-\-threads\fR)
.TP
.B OMP_WAIT_POLICY
\fBpassive\fR lets idle worker threads sleep at once: better on a machine whose cores
other jobs share
.TP
.B GOMP_SPINCOUNT
how long idle worker threads spin before they sleep; \fBkeithray view\fR runs itself
again with 10000 (about 0.1 ms) unless this or \fBOMP_WAIT_POLICY\fR is set
.TP
.BR DISPLAY ", " WAYLAND_DISPLAY
the display \fBkeithray view\fR opens its window on
.SH "EXIT STATUS"
0 on success, 1 when a scene or image could not be read, rendered or written (compare: the
images differ), 2 on bad usage.
.SH "SEE ALSO"
.BR mpirun (1);
README.md and the pages it links, installed in share/doc/keithray (docs/install.md: this layout).
)";
    return out;
}

std::string bash_completion(const std::vector<CommandHelp>& commands, const std::vector<std::string>& top_flags) {
    std::vector<std::string> names;
    for (const CommandHelp& c : commands) names.push_back(c.name);
    for (const std::string& f : top_flags) names.push_back(f);
    std::string out;
    out += "# bash completion for keithray, generated by `keithray --completion bash` from the help\n"
           "# texts and the flag table `keithray --help` prints from; installed as\n"
           "# share/bash-completion/completions/keithray.\n";
    out += "_keithray_files() {  # $1: a glob of the names to offer besides folders (empty: all)\n"
           "    local IFS=$'\\n'\n"
           "    compopt -o filenames 2>/dev/null\n"
           "    if [ -n \"$1\" ]; then\n"
           "        COMPREPLY+=($(compgen -d -- \"$cur\") $(compgen -f -X \"!$1\" -- \"$cur\"))\n"
           "    else\n"
           "        COMPREPLY+=($(compgen -f -- \"$cur\"))\n"
           "    fi\n"
           "}\n";
    out += "_keithray() {\n"
           "    local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} command=${COMP_WORDS[1]}\n"
           "    COMPREPLY=()\n"
           "    if [ \"$COMP_CWORD\" -le 1 ]; then\n"
           "        COMPREPLY=($(compgen -W '" + shell_words(names) + "' -- \"$cur\"))\n"
           "        return\n"
           "    fi\n"
           "    case $command in\n";
    for (const CommandHelp& c : commands) {
        out += "    " + c.name + ")\n";
        // The values: name flags offer their names, file flags file names, the rest nothing.
        std::vector<std::pair<std::string, std::vector<std::string>>> name_values = c.names;
        std::vector<std::string> optional_value;
        for (const SharedFlag& f : shared_flags())
            if (f.kind == FlagKind::name && c.help.find(std::string(f.name) + " ") != std::string::npos) {
                name_values.push_back({std::string(f.name), split_names(f.names())});
                if (!f.bare.empty()) optional_value.push_back(std::string(f.name));
            }
        out += "        case $prev in\n";
        for (const auto& [flag, values] : name_values) {
            const bool optional = std::find(optional_value.begin(), optional_value.end(), flag) != optional_value.end();
            out += "        " + flag + ")\n";
            if (optional) out += "            if [[ $cur != -* ]]; then\n    ";
            out += "            COMPREPLY=($(compgen -W '" + shell_words(values) + "' -- \"$cur\"))\n";
            if (optional) out += "            fi\n            ;;\n";  // then flags and files as after no flag
            else out += "            return ;;\n";
        }
        std::vector<std::string> file_flags, dir_flags, value_flags;
        for (const HelpOption& o : help_options(c.help)) {
            if (o.value.empty() || o.value[0] == '[') continue;
            const bool named = std::any_of(name_values.begin(), name_values.end(),
                                           [&](const auto& nv) { return nv.first == o.flags.back(); });
            if (named) continue;
            for (const std::string& f : o.flags)
                (takes_file(o.value) ? file_flags : o.value.find("DIR") != std::string::npos ? dir_flags : value_flags)
                    .push_back(f);
        }
        if (!file_flags.empty()) {
            std::string alts;
            for (const std::string& f : file_flags) alts += (alts.empty() ? "" : "|") + f;
            out += "        " + alts + ")\n            _keithray_files ''\n            return ;;\n";
        }
        if (!dir_flags.empty()) {
            std::string alts;
            for (const std::string& f : dir_flags) alts += (alts.empty() ? "" : "|") + f;
            out += "        " + alts + ")\n            compopt -o filenames 2>/dev/null\n"
                   "            COMPREPLY=($(compgen -d -- \"$cur\"))\n            return ;;\n";
        }
        if (!value_flags.empty()) {
            std::string alts;
            for (const std::string& f : value_flags) alts += (alts.empty() ? "" : "|") + f;
            out += "        " + alts + ")\n            return ;;  # a number or a list: nothing to offer\n";
        }
        out += "        esac\n";
        out += "        if [[ $cur == -* ]]; then\n"
               "            COMPREPLY+=($(compgen -W '" + shell_words(help_flags(c.help, c.name)) + "' -- \"$cur\"))\n";
        if (c.positional == "scene") out += "        else\n            _keithray_files '*.json'\n";
        else if (c.positional == "image") out += "        else\n            _keithray_files ''\n";
        out += "        fi\n        ;;\n";
    }
    out += "    esac\n}\ncomplete -F _keithray keithray\n";
    return out;
}

}  // namespace kr
