#include "core/text.h"

#include <cstdint>
#include <cstdio>

namespace kr {

namespace {

// Length of the well-formed UTF-8 sequence starting at text[i] (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF), or 0 if the byte there starts none.
size_t utf8_length(std::string_view text, size_t i, uint32_t& code_point) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[i + k]); };
    const unsigned char lead = byte(0);
    size_t length = 0;
    uint32_t lowest = 0;
    if (lead < 0x80) {
        code_point = lead;
        return 1;
    } else if ((lead & 0xE0) == 0xC0) {
        length = 2, lowest = 0x80, code_point = lead & 0x1F;
    } else if ((lead & 0xF0) == 0xE0) {
        length = 3, lowest = 0x800, code_point = lead & 0x0F;
    } else if ((lead & 0xF8) == 0xF0) {
        length = 4, lowest = 0x10000, code_point = lead & 0x07;
    } else {
        return 0;
    }
    if (i + length > text.size()) return 0;
    for (size_t k = 1; k < length; ++k) {
        if ((byte(k) & 0xC0) != 0x80) return 0;
        code_point = (code_point << 6) | (byte(k) & 0x3F);
    }
    if (code_point < lowest || code_point > 0x10FFFF || (code_point >= 0xD800 && code_point <= 0xDFFF)) return 0;
    return length;
}

// Characters a terminal or a log reader may act on: C0 controls, DEL, C1 controls (0x9B is
// a one-byte CSI) and the line and paragraph separators.
bool needs_escape(uint32_t c) {
    return c < 0x20 || c == 0x7F || (c >= 0x80 && c <= 0x9F) || c == 0x2028 || c == 0x2029;
}

}  // namespace

std::string utf8_escaped(std::string_view text) {
    std::string out;
    for (size_t i = 0; i < text.size();) {
        uint32_t c = 0;
        const size_t length = utf8_length(text, i, c);
        if (length) {
            out.append(text.substr(i, length));
            i += length;
            continue;
        }
        char escape[8];
        std::snprintf(escape, sizeof escape, "\\x%02X", static_cast<unsigned char>(text[i++]));
        out += escape;
    }
    return out;
}

std::string quote_user_text(std::string_view text, size_t max_bytes) {
    std::string out = "\"";
    size_t i = 0;
    while (i < text.size()) {
        uint32_t c = 0;
        const size_t length = utf8_length(text, i, c);
        if (i + (length ? length : 1) > max_bytes) break;
        char escape[12];
        if (length == 0) {
            std::snprintf(escape, sizeof escape, "\\x%02X", static_cast<unsigned char>(text[i]));
            out += escape;
            ++i;
            continue;
        }
        if (c == '"' || c == '\\') {
            out += '\\';
            out += static_cast<char>(c);
        } else if (c == '\n') {
            out += "\\n";
        } else if (c == '\r') {
            out += "\\r";
        } else if (c == '\t') {
            out += "\\t";
        } else if (needs_escape(c)) {
            std::snprintf(escape, sizeof escape, c < 0x80 ? "\\x%02X" : "\\u%04X", static_cast<unsigned>(c));
            out += escape;
        } else {
            out.append(text.substr(i, length));
        }
        i += length;
    }
    out += '"';
    if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
    return out;
}

std::string show_user_text(std::string_view text, size_t max_bytes) {
    bool plain = text.size() <= max_bytes && !text.empty();
    for (size_t i = 0; plain && i < text.size();) {
        uint32_t c = 0;
        const size_t length = utf8_length(text, i, c);
        plain = length > 0 && !needs_escape(c);
        i += length;
    }
    return plain ? std::string(text) : quote_user_text(text, max_bytes);
}

}  // namespace kr
