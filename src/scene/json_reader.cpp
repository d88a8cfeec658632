// The hardened JSON reader under the scene loader: nesting bounded before parsing, a DOM
// built from SAX events (linear, duplicate keys refused, the JSON pointer of every error),
// overflowing numbers refused, and a DOM freed without allocating when memory ran out.
#include "scene/json_reader.h"

#include <optional>
#include <unordered_set>
#include <utility>

#include "core/memory.h"
#include "core/text.h"

namespace kr {

namespace {

constexpr int kMaxNesting = 64;

// nlohmann's DOM (and its destructor) are recursive, so hostile nesting is refused before
// parsing. Brackets inside strings do not count.
void check_nesting(std::string_view text, const std::string& file) {
    int depth = 0, line = 1, column = 0;
    bool in_string = false, escaped = false;
    for (char c : text) {
        if (c == '\n') {
            ++line;
            column = 0;
        } else {
            ++column;
        }
        if (in_string) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') in_string = false;
            continue;
        }
        if (c == '"') {
            in_string = true;
        } else if (c == '{' || c == '[') {
            if (++depth > kMaxNesting)
                throw SceneError(file, "",
                                 "JSON nesting deeper than " + std::to_string(kMaxNesting) +
                                     " levels at line " + std::to_string(line) + ", column " +
                                     std::to_string(column));
        } else if ((c == '}' || c == ']') && depth > 0) {
            --depth;
        }
    }
}

// Builds the DOM from nlohmann's SAX events. Doing it here rather than with a parser
// callback keeps parsing linear (the callback parser rescans the parent array at every
// object end), and lets us refuse duplicate keys and know the JSON pointer of the value
// being parsed, where nlohmann itself only knows a byte offset.
//
// An object's members are gathered in a vector of (key, value) pairs and moved into its
// ordered_map when it closes, with one allocation of the exact size. The ordered_map is a
// std::vector of pair<const string, Json>, whose const key makes the pair's move constructor
// one that may throw, so a growing ordered_map copies its elements: appending the fourth key
// of a scene's top level deep-copied its "shapes" array (100,000 objects), and a bad_alloc
// in that copy destroyed the partial copy, whose nlohmann destructor allocates (its heap
// stack), threw again out of a noexcept destructor, and aborted the process.
class DomBuilder : public nlohmann::json_sax<Json> {
public:
    Json root;
    // Whatever is left of the DOM (a partial one when parsing stopped, and the members of
    // the objects still open) is freed without allocating: this may run while memory is
    // exhausted.
    ~DomBuilder() override { free(); }
    void free() noexcept {
        for (Level& level : levels_)
            for (auto& member : level.members) release(member.second);
        release(root);
    }
    // Set when parsing stopped on our own finding rather than a syntax error.
    std::optional<std::string> duplicate_key;
    std::string error_pointer;                 // where parsing stopped
    int error_id = 0;                          // nlohmann's exception id (101, 406, ...)
    std::string error_text;

    bool null() override { return add(Json(nullptr)); }
    bool boolean(bool v) override { return add(Json(v)); }
    bool number_integer(number_integer_t v) override { return add(Json(v)); }
    bool number_unsigned(number_unsigned_t v) override { return add(Json(v)); }
    bool number_float(number_float_t v, const string_t&) override { return add(Json(v)); }
    bool string(string_t& v) override { return add(Json(std::move(v))); }
    bool binary(binary_t&) override { return add(Json(nullptr)); }  // not produced by JSON text

    bool start_object(std::size_t) override { return open(Json::object()); }
    bool start_array(std::size_t) override { return open(Json::array()); }
    bool key(string_t& k) override {
        Level& top = levels_.back();
        top.key = k;
        if (!top.keys.insert(k).second) {
            duplicate_key = k;
            error_pointer = pointer();
            return false;
        }
        return true;
    }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }

    bool parse_error(std::size_t, const std::string&, const nlohmann::json::exception& e) override {
        error_id = e.id;
        error_text = e.what();
        error_pointer = pointer();
        return false;
    }

private:
    struct Level {
        Json* value;
        std::string key;   // objects: the key whose value is being parsed
        size_t count = 0;  // arrays: elements completed so far = index of the current one
        std::unordered_set<std::string> keys;
        std::vector<std::pair<std::string, Json>> members;  // objects: their members so far (movable)
    };

    // Pointer of the value being parsed now.
    std::string pointer() const {
        std::string out;
        for (const Level& level : levels_)
            out = level.value->is_object() ? child(out, level.key) : child(out, level.count);
        return out;
    }

    // Stores a value in the innermost container and returns where it now lives. Only that
    // container grows while it is open, so the pointers held in levels_ stay valid. Arrays
    // grow by moving their elements (basic_json's move constructor is noexcept).
    Json* place(Json&& value) {
        if (levels_.empty()) {
            root = std::move(value);
            return &root;
        }
        Level& top = levels_.back();
        if (top.value->is_array()) {
            auto& array = top.value->get_ref<Json::array_t&>();
            array.push_back(std::move(value));
            return &array.back();
        }
        top.members.emplace_back(top.key, std::move(value));
        return &top.members.back().second;
    }

    bool add(Json&& value) {
        place(std::move(value));
        element_done();
        return true;
    }
    bool open(Json&& container) {
        Json* where = place(std::move(container));
        levels_.push_back({where, {}, 0, {}, {}});
        return true;
    }
    bool close() {
        Level& top = levels_.back();
        if (top.value->is_object()) {
            // Keys are known unique (key() checked), so skip ordered_map's linear lookup; the
            // exact reserve means no reallocation, so every value is moved, none copied.
            auto& object = top.value->get_ref<Json::object_t&>();
            object.reserve(top.members.size());
            for (auto& [key, value] : top.members) object.Container::emplace_back(std::move(key), std::move(value));
        }
        levels_.pop_back();
        element_done();
        return true;
    }
    void element_done() {
        if (!levels_.empty() && levels_.back().value->is_array()) ++levels_.back().count;
    }

    std::vector<Level> levels_;
};

}  // namespace


// RFC 6901 escaping: only '~' and '/' are special; spaces stay as they are.
std::string child(const std::string& pointer, std::string_view key) {
    std::string out = pointer + '/';
    for (char c : key) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

std::string child(const std::string& pointer, size_t index) {
    return pointer + '/' + std::to_string(index);
}

// "a", "b", "c": the form used for lists of keys and ids.
std::string quoted_list(const std::vector<std::string>& items) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i > 0) out += ", ";
        out += in_quotes(items[i]);
    }
    return out;
}

std::string number_text(const Json& j) { return j.dump(); }

// What a value is, for "expected X, got Y" messages.
std::string describe(const Json& j) {
    switch (j.type()) {
        case Json::value_t::string: return "string " + in_quotes(j.get_ref<const std::string&>());
        case Json::value_t::boolean: return j.get<bool>() ? "boolean true" : "boolean false";
        case Json::value_t::null: return "null";
        case Json::value_t::object: return "an object";
        case Json::value_t::array:
            return j.size() == 1 ? "an array of 1 element"
                                 : "an array of " + std::to_string(j.size()) + " elements";
        case Json::value_t::number_integer:
        case Json::value_t::number_unsigned:
        case Json::value_t::number_float: return "number " + number_text(j);
        default: return "an unsupported value";
    }
}

SceneError out_of_memory(const std::string& file, std::string_view text) {
    return SceneError(file, "", "not enough memory for the scene (" + format_bytes(text.size()) + " of JSON)");
}

Json parse_json(std::string_view text, const std::string& file) {
    check_nesting(text, file);
    DomBuilder builder;
    try {
        if (Json::sax_parse(text.begin(), text.end(), &builder)) return std::move(builder.root);
    } catch (const std::bad_alloc&) {
        builder.free();  // before the message's strings are allocated
        throw out_of_memory(file, text);
    } catch (const std::length_error&) {
        builder.free();
        throw out_of_memory(file, text);
    }

    if (builder.duplicate_key)
        throw SceneError(file, builder.error_pointer,
                         "duplicate key " + in_quotes(*builder.duplicate_key) +
                             "; each key may appear only once in an object");
    if (builder.error_id == 406) {
        // A float literal such as 1e999 that overflows to infinity: nlohmann's text
        // quotes it as "number overflow parsing '1e999'".
        const std::string& what = builder.error_text;
        const size_t open = what.find('\''), close = what.rfind('\'');
        const std::string token =
            open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : "";
        throw SceneError(file, builder.error_pointer,
                         "number " + show_user_text(token, 40) + " is not a finite number; expected a finite number");
    }
    // nlohmann's text reads "[json.exception.parse_error.101] parse error at line 4, ...".
    std::string detail = builder.error_text;
    const size_t at = detail.find("at line ");
    if (at != std::string::npos) detail = detail.substr(at);
    // Its "last read" excerpt is the file's text (a whole token: a million-digit number is a
    // million bytes), so it is quoted and bounded like any user text.
    const std::string last_read = "; last read: '";
    if (const size_t from = detail.find(last_read); from != std::string::npos) {
        const size_t begin = from + last_read.size(), end = detail.rfind('\'');
        const std::string token = detail.substr(begin, end > begin ? end - begin : std::string::npos);
        detail = detail.substr(0, from) + "; last read: " + quote_user_text(token, 40) +
                 (end > begin && end + 1 < detail.size() ? detail.substr(end + 1) : "");
    }
    throw SceneError(file, "", "malformed JSON " + show_user_text(detail, 400));
}


}  // namespace kr
