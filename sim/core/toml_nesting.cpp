#include "sim/core/toml_nesting.hpp"

#include <vector>

#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim {

void check_toml_nesting(std::string_view text, std::string_view source) {
    enum class Mode { key, value, header };
    struct Open {
        char bracket;  // '[' for an array, '{' for an inline table
        int depth;     // the depth of the array or table itself
    };
    std::vector<Open> open;
    Mode mode = Mode::key;
    int table_depth = 0;  // of the last [header] or [[header]]
    int key_parts = 0;    // of the (dotted) key being read
    int value_depth = 0;  // of the value being read
    int line = 1;
    const auto check = [&](int depth) {
        if (depth > kMaxTomlNesting)
            throw Error(fmt::format("{}:{}: TOML nested more than {} levels deep (table headers, "
                                    "dotted keys, arrays and inline tables all count); flatten "
                                    "the file",
                                    source, line, kMaxTomlNesting));
    };
    const auto container_depth = [&] { return open.empty() ? table_depth : open.back().depth; };
    const auto start_key = [&] {
        mode = Mode::key;
        key_parts = 0;
    };
    const size_t n = text.size();
    for (size_t i = 0; i < n; ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
            if (open.empty()) start_key();  // a statement ends; arrays may span lines
            continue;
        }
        if (c == '#') {  // a comment runs to the end of the line
            while (i + 1 < n && text[i + 1] != '\n')
                ++i;
            continue;
        }
        if (c == '"' || c == '\'') {  // a string or quoted key: skip it, counting its lines
            const bool triple = i + 2 < n && text[i + 1] == c && text[i + 2] == c;
            const auto closes = [&](size_t at) {
                return text[at] == c &&
                       (!triple || (at + 2 < n && text[at + 1] == c && text[at + 2] == c));
            };
            for (i += triple ? 3 : 1; i < n && !closes(i); ++i) {
                if (text[i] == '\n') {
                    if (!triple) break;  // an unterminated one-line string: toml++ reports it
                    ++line;
                }
                if (c == '"' && text[i] == '\\' && i + 1 < n && text[i + 1] != '\n') ++i;
            }
            if (i < n && text[i] == '\n') {
                --i;  // the newline ends the statement
            } else if (triple) {
                i += 2;
                while (i + 1 < n && text[i + 1] == c)  // """a"""" ends in a quote
                    ++i;
            }
            if (mode != Mode::value && key_parts == 0) {
                key_parts = 1;
                check(container_depth() + key_parts);
            }
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\r') continue;
        switch (mode) {
        case Mode::header:
            if (c == '.') {
                check(++key_parts);
            } else if (c == ']') {
                table_depth = key_parts;
                while (i + 1 < n && text[i + 1] == ']')
                    ++i;
                mode = Mode::value;  // nothing but a comment may follow on the line
            } else if (c != '[' && key_parts == 0) {
                key_parts = 1;
            }
            break;
        case Mode::key:
            if (c == '[' && open.empty() && key_parts == 0) {
                mode = Mode::header;
                table_depth = 0;
            } else if (c == '.') {
                check(container_depth() + ++key_parts);
            } else if (c == '=') {
                mode = Mode::value;
                value_depth = container_depth() + key_parts;
            } else if (c == '}' && !open.empty()) {  // an empty inline table, or a trailing ','
                open.pop_back();
                mode = Mode::value;
                if (!open.empty() && open.back().bracket == '[')
                    value_depth = open.back().depth + 1;
            } else if (key_parts == 0) {
                key_parts = 1;
                check(container_depth() + key_parts);
            }
            break;
        case Mode::value:
            if (c == '[' || c == '{') {
                open.push_back({c, value_depth});
                if (c == '{') {
                    start_key();
                } else {
                    check(++value_depth);
                }
            } else if ((c == ']' || c == '}') && !open.empty()) {
                open.pop_back();
                if (!open.empty() && open.back().bracket == '[')
                    value_depth = open.back().depth + 1;
            } else if (c == ',' && !open.empty()) {
                if (open.back().bracket == '{')
                    start_key();
                else
                    value_depth = open.back().depth + 1;
            }
            break;
        }
    }
}

}  // namespace tpsim
