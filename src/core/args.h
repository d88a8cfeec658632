// Command-line value parsing shared by `keithray render`, `bench` and `view`: the whole
// text must be the value, and a bad one becomes a UsageError naming the flag, its range and
// the text given (quoted and bounded: core/text.h).
#pragma once

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/text.h"

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
    // The next argument, not taken (nullptr at the end).
    const char* peek() const { return index_ + 1 < argc_ ? argv_[index_ + 1] : nullptr; }
    std::string value() {
        if (index_ + 1 >= argc_) throw UsageError{show_user_text(arg_, 40) + " needs a value"};
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

inline UsageError unknown_option(const std::string& arg) { return {"unknown option " + quote_user_text(arg, 40)}; }

// A range bound as people write it: 4096, 1e+06, 0.0001.
inline std::string bound_text(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.10g", v);
    return text;
}

// True if all of `text` reads as a decimal number (stored in `value`): no leading blanks,
// no hexadecimal, no "nan" or "inf".
inline bool read_number(const std::string& text, double& value) {
    if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
    size_t used = 0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {  // not a number, or out of double's range
        return false;
    }
    return used == text.size();
}

// A number in [lo, hi], or (lo, hi] when lo_open.
inline double parse_number(const std::string& flag, const std::string& text, double lo, double hi,
                           bool lo_open = false) {
    double v = 0;
    if (!read_number(text, v) || !((lo_open ? v > lo : v >= lo) && v <= hi))
        throw UsageError{flag + " expects a number in " + (lo_open ? "(" : "[") + bound_text(lo) + ", " +
                         bound_text(hi) + "], got " + quote_user_text(text, 40)};
    return v;
}

inline long long parse_integer(const std::string& flag, const std::string& text, long long lo, long long hi) {
    size_t used = 0;
    long long value = 0;
    const bool digits = !text.empty() && text.find_first_not_of("0123456789+-") == std::string::npos;
    try {
        if (digits) value = std::stoll(text, &used);
    } catch (const std::exception&) {  // out of long long's range
        used = 0;
    }
    if (!digits || used != text.size() || value < lo || value > hi)
        throw UsageError{flag + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "], got " + quote_user_text(text, 40)};
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
    if (!value) throw UsageError{flag + " expects " + names.list() + ", got " + quote_user_text(text, 40)};
    return *value;
}

}  // namespace kr
