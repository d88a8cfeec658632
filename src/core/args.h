// Command-line value parsing shared by `keithray render`, `bench` and `view`: the whole
// text must be the value, and a bad one becomes a UsageError naming the flag.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace kr {

struct UsageError {
    std::string message;  // empty: --help was asked for
};

// Walks the arguments after the subcommand:
//   for (ArgCursor args(argc, argv); args.next();) { ... args.arg() ... args.value() ... }
// value() takes the next argument as the current flag's value.
class ArgCursor {
public:
    ArgCursor(int argc, char** argv, int first = 2) : argc_(argc), argv_(argv), index_(first - 1) {}
    bool next() {
        if (++index_ >= argc_) return false;
        arg_ = argv_[index_];
        return true;
    }
    const std::string& arg() const { return arg_; }
    std::string value() {
        if (index_ + 1 >= argc_) throw UsageError{arg_ + " needs a value"};
        return argv_[++index_];
    }

private:
    int argc_;
    char** argv_;
    int index_;
    std::string arg_;
};

// The exit status for a UsageError of a subcommand with `usage` text: --help prints the usage
// on stdout (0); an error prints itself and the usage on stderr (2).
inline int report_usage(const UsageError& e, const char* usage) {
    if (!e.message.empty()) std::fprintf(stderr, "error: %s\n", e.message.c_str());
    std::fprintf(e.message.empty() ? stdout : stderr, "%s", usage);
    return e.message.empty() ? 0 : 2;
}

// True if all of `text` reads as a number (stored in `value`).
inline bool read_number(const std::string& text, double& value) {
    size_t used = 0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {
        return false;
    }
    return !text.empty() && used == text.size();
}

inline double parse_number(const std::string& flag, const std::string& text, double lo, double hi) {
    double v = 0;
    if (!read_number(text, v) || !(v >= lo && v <= hi))
        throw UsageError{flag + " expects a number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "], got \"" + text + "\""};
    return v;
}

// A number in (0, 1e9): durations and error targets.
inline double parse_positive(const std::string& flag, const std::string& text) {
    double v = 0;
    if (!read_number(text, v) || !(v > 0 && v < 1e9))
        throw UsageError{flag + " expects a positive number, got \"" + text + "\""};
    return v;
}

inline long long parse_integer(const std::string& flag, const std::string& text, long long lo, long long hi) {
    size_t used = 0;
    long long value = 0;
    try {
        value = std::stoll(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || text.empty() || value < lo || value > hi)
        throw UsageError{flag + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "], got \"" + text + "\""};
    return value;
}

// The items of a comma-separated list ("a,b,c"); an empty text is one empty item.
inline std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> items(1);
    for (char c : text) {
        if (c == ',') items.emplace_back();
        else items.back() += c;
    }
    return items;
}

// One of an EnumNames table's names.
template <typename Names>
auto parse_name(const std::string& flag, const std::string& text, const Names& names) {
    const auto value = names.parse(text);
    if (!value) throw UsageError{flag + " expects " + names.list() + ", got \"" + text + "\""};
    return *value;
}

}  // namespace kr
