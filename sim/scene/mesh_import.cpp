#include "sim/scene/mesh_import.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/core/file_extension.hpp"
#include "sim/core/input_file.hpp"
#include "sim/core/module.hpp"
#include "sim/scene/mesh_reader.hpp"

namespace tpsim::scene {

namespace {

/// Every file tpsim reads for a mesh (the mesh, an OBJ's material library, a glTF's buffers) is
/// at most this big; assimp holds a file in memory a few times over while it converts it.
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{1} << 30;
/// The most vertices or faces a PLY or OFF file may declare: beyond the scene's triangle limit,
/// and checked before assimp allocates for them.
constexpr uint64_t kMaxElementCount = uint64_t{1} << 26;
/// glTF is JSON; its reader recurses per nesting level. Real files nest fewer than 10 levels.
constexpr int kMaxJsonNesting = 64;

/// The formats tpsim offers: each has a reader that was fuzzed, and tpsim checks what that
/// reader does not (see docs/scenes.md). Assimp reads many more, not all of them safely.
constexpr std::string_view kMeshFormats[] = {".obj", ".ply", ".off", ".stl", ".gltf", ".glb"};
constexpr std::string_view kMeshFormatList = ".obj, .ply, .off, .stl, .gltf or .glb";

[[noreturn]] void malformed(const std::string& where, std::string_view format,
                            const std::string& why) {
    throw Error(fmt::format("{}: malformed or truncated {} file: {}", where, format, why));
}

/// A PLY scalar type: its size in bytes (0 if unknown) and whether it is a signed integer or a
/// float.
struct PlyType {
    size_t size = 0;
    bool is_signed = false, is_float = false;
};

PlyType ply_type(const std::string& type) {
    if (type == "char" || type == "int8") return {1, true};
    if (type == "uchar" || type == "uint8") return {1};
    if (type == "short" || type == "int16") return {2, true};
    if (type == "ushort" || type == "uint16") return {2};
    if (type == "int" || type == "int32") return {4, true};
    if (type == "uint" || type == "uint32") return {4};
    if (type == "float" || type == "float32") return {4, true, true};
    if (type == "double" || type == "float64") return {8, true, true};
    return {};
}

/// Assimp 5.2's PLY reader loops forever on a truncated header, aborts (ai_assert) on a truncated
/// body or a face without vertices, and allocates for whatever counts the header claims. So PLY
/// files are walked here first: the header must end, every element must fit in the body (an
/// ASCII item on its own line), and every face must have vertices, all within range.
void check_ply(const std::string& where, const std::string& bytes) {
    const auto fail = [&](const std::string& why) { malformed(where, "PLY", why); };
    struct Property {
        PlyType type, count_type;  // count_type.size != 0: a list
        bool vertex_indices = false;
    };
    struct Element {
        std::string name;
        uint64_t count = 0;
        std::vector<Property> properties;
    };
    std::vector<Element> elements;
    std::string format;
    size_t at = 0;  // where the next header line starts
    for (bool ended = false; !ended;) {
        const size_t eol = bytes.find('\n', at);
        if (eol == std::string::npos) fail("no end_header");
        std::istringstream words(bytes.substr(at, eol - at));
        at = eol + 1;
        std::string word;
        words >> word;
        if (word == "format") {
            words >> format;
        } else if (word == "element") {
            Element element;
            if (!(words >> element.name >> element.count))
                fail("bad element line '" + words.str() + "'");
            if (element.count > kMaxElementCount)
                fail(fmt::format("element {} has {} items, more than the {} tpsim reads",
                                 element.name, element.count, kMaxElementCount));
            elements.push_back(element);
        } else if (word == "property") {
            if (elements.empty()) fail("property before any element");
            std::string type, count_type, item_type, name;
            words >> type;
            Property property;
            if (type == "list") {
                words >> count_type >> item_type >> name;
                property.type = ply_type(item_type);
                property.count_type = ply_type(count_type);
                if (property.count_type.size == 0 || property.count_type.is_float)
                    fail("bad list property '" + words.str() + "'");
            } else {
                words >> name;
                property.type = ply_type(type);
            }
            if (property.type.size == 0) fail("unknown property type in '" + words.str() + "'");
            property.vertex_indices = name == "vertex_indices" || name == "vertex_index";
            if (property.vertex_indices && property.type.is_float)
                fail("vertex indices must have an integer type, not '" + item_type + "'");
            elements.back().properties.push_back(property);
        } else if (word == "end_header") {
            ended = true;
        }
    }
    const bool ascii = format == "ascii";
    const bool big_endian = format == "binary_big_endian";
    if (!ascii && !big_endian && format != "binary_little_endian")
        fail("unknown format '" + format + "'");

    uint64_t vertices = 0;
    bool has_faces = false;
    for (const Element& element : elements) {
        if (element.count != 0 && element.properties.empty())
            fail("element " + element.name + " has items but no properties");
        if (element.name == "vertex") vertices = element.count;
        if ((element.name == "face" || element.name == "tristrips") && element.count != 0)
            has_faces = true;
    }
    if (!has_faces)
        throw Error(fmt::format("{}: the PLY file has no faces (a point cloud?); tpsim "
                                "renders triangles",
                                where));
    // A face's vertex index, in range (tristrips separate strips with -1).
    const auto check_index = [&](const Element& element, uint64_t item, int64_t index) {
        const int64_t lowest = element.name == "tristrips" ? -1 : 0;
        if (index < lowest || index >= int64_t(vertices))
            fail(fmt::format("{} {} refers to vertex {} of {}", element.name, item, index,
                             vertices));
    };

    if (ascii) {
        // Item by item, a line each, as assimp reads them: a line must hold its item's values
        // (assimp ignores any beyond them).
        std::istringstream body(bytes.substr(at));
        std::string line, token;
        std::istringstream item;
        const auto next_token = [&] {
            if (!(item >> token)) fail("body ends early");
        };
        const auto next_integer = [&] {
            int64_t value = 0;
            next_token();
            const auto [end, error] =
                std::from_chars(token.data(), token.data() + token.size(), value);
            if (error != std::errc() || end != token.data() + token.size())
                fail("'" + token + "' is not an integer");
            return value;
        };
        for (const Element& element : elements)
            for (uint64_t i = 0; i < element.count; ++i) {
                do
                    if (!std::getline(body, line)) fail("body ends early");
                while (line.find_first_not_of(" \t\r") == std::string::npos);
                item.clear();
                item.str(line);
                for (const Property& property : element.properties) {
                    int64_t items = 1;
                    if (property.count_type.size != 0) {
                        items = next_integer();
                        if (items < 0) fail(fmt::format("a list of {} items", items));
                        if (property.vertex_indices && items == 0)
                            fail(fmt::format("{} {} has no vertices", element.name, i));
                    }
                    for (int64_t k = 0; k < items; ++k)
                        if (property.vertex_indices)
                            check_index(element, i, next_integer());
                        else
                            next_token();
                }
            }
        return;
    }
    const std::string_view body = std::string_view(bytes).substr(at);
    // The integer of `type` at body[offset].
    const auto read = [&](const PlyType& type, uint64_t offset) {
        uint64_t value = 0;
        for (size_t b = 0; b < type.size; ++b) {
            const size_t byte = big_endian ? type.size - 1 - b : b;
            value |= uint64_t(static_cast<unsigned char>(body[offset + byte])) << (8 * b);
        }
        if (type.is_signed && type.size < 8 && (value >> (8 * type.size - 1)) != 0)
            value |= ~uint64_t(0) << (8 * type.size);  // sign-extend
        return int64_t(value);
    };
    uint64_t offset = 0;
    for (const Element& element : elements) {
        if (element.count == 0) continue;  // it may have no properties, so no item size
        const bool has_list = std::any_of(element.properties.begin(), element.properties.end(),
                                          [](const Property& p) { return p.count_type.size != 0; });
        if (!has_list) {  // fixed-size items: one multiplication, no walk
            uint64_t item_bytes = 0;
            for (const Property& property : element.properties)
                item_bytes += property.type.size;
            if (element.count > (body.size() - offset) / item_bytes) fail("body ends early");
            offset += element.count * item_bytes;
            continue;
        }
        // Every item takes at least one byte, so this walk is bounded by the file's size.
        for (uint64_t i = 0; i < element.count; ++i)
            for (const Property& property : element.properties) {
                int64_t items = 1;
                if (property.count_type.size != 0) {
                    if (property.count_type.size > body.size() - offset) fail("body ends early");
                    items = read(property.count_type, offset);
                    offset += property.count_type.size;
                    if (items < 0) fail(fmt::format("a list of {} items", items));
                    if (property.vertex_indices && items == 0)
                        fail(fmt::format("{} {} has no vertices", element.name, i));
                }
                if (uint64_t(items) > (body.size() - offset) / property.type.size)
                    fail("body ends early");
                for (int64_t k = 0; k < items; ++k, offset += property.type.size)
                    if (property.vertex_indices)
                        check_index(element, i, read(property.type, offset));
            }
    }
}

/// Assimp 5.2's OFF reader allocates for the vertex count its header claims, clamps a vertex
/// index past the end to the last vertex, and reads a face line by line. So OFF files are
/// walked here first, line by line as assimp does: counts that the file can hold, three
/// coordinates per vertex, and faces of 1 to 9 vertices (assimp's limit) within range.
void check_off(const std::string& where, const std::string& bytes) {
    const auto fail = [&](const std::string& why) { malformed(where, "OFF", why); };
    std::vector<std::vector<std::string_view>> lines;  // the words of each non-empty line
    for (size_t at = 0; at < bytes.size();) {
        size_t eol = bytes.find('\n', at);
        if (eol == std::string::npos) eol = bytes.size();
        std::string_view line = std::string_view(bytes).substr(at, eol - at);
        at = eol + 1;
        line = line.substr(0, line.find('#'));
        std::vector<std::string_view> words;
        for (size_t i = 0; i < line.size();) {
            const size_t begin = line.find_first_not_of(" \t\r", i);
            if (begin == std::string_view::npos) break;
            const size_t end = std::min(line.find_first_of(" \t\r", begin), line.size());
            words.push_back(line.substr(begin, end - begin));
            i = end;
        }
        if (!words.empty()) lines.push_back(std::move(words));
    }
    const auto integer = [&](std::string_view word, const char* what) {
        int64_t value = 0;
        const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
        if (error != std::errc() || end != word.data() + word.size())
            fail(fmt::format("{} '{}' is not a whole number", what, word));
        return value;
    };
    if (lines.empty() || !lines[0][0].ends_with("OFF")) fail("it does not start with OFF");
    if (lines[0].size() > 1 && lines[0][1] == "BINARY") fail("binary OFF is not supported");
    // The counts follow the keyword on its line, or are the next line.
    std::vector<std::string_view> counts(lines[0].begin() + 1, lines[0].end());
    size_t next = 1;
    if (counts.empty() && lines.size() > 1) counts = lines[next++];
    if (counts.size() < 2) fail("no vertex and face counts after OFF");
    const int64_t vertices = integer(counts[0], "the vertex count");
    const int64_t faces = integer(counts[1], "the face count");
    if (vertices < 0 || faces < 0) fail("a negative count");
    if (uint64_t(vertices) > kMaxElementCount || uint64_t(faces) > kMaxElementCount)
        fail(fmt::format("{} vertices and {} faces, more than the {} tpsim reads", vertices, faces,
                         kMaxElementCount));
    if (faces == 0)
        throw Error(fmt::format("{}: the OFF file has no faces; tpsim renders triangles", where));
    if (size_t(vertices + faces) > lines.size() - next)
        fail(fmt::format("the header claims {} vertices and {} faces, the file has {} lines",
                         vertices, faces, lines.size() - next));
    for (int64_t v = 0; v < vertices; ++v, ++next)
        if (lines[next].size() < 3) fail(fmt::format("vertex {} has fewer than 3 coordinates", v));
    for (int64_t f = 0; f < faces; ++f, ++next) {
        const std::vector<std::string_view>& face = lines[next];
        const int64_t corners = integer(face[0], "a face's vertex count");
        if (corners < 1 || corners > 9)
            fail(fmt::format("face {} has {} vertices; tpsim reads faces of 1 to 9", f, corners));
        if (size_t(corners) >= face.size())
            fail(fmt::format("face {} lists fewer than its {} vertices", f, corners));
        for (int64_t k = 1; k <= corners; ++k) {
            const int64_t index = integer(face[k], "a vertex index");
            if (index < 0 || index >= vertices)
                fail(fmt::format("face {} refers to vertex {} of {}", f, index, vertices));
        }
    }
}

/// The deepest bracket nesting of a JSON text, strings skipped; stops counting past `limit`.
int json_nesting(std::string_view json, int limit) {
    int depth = 0, deepest = 0;
    for (size_t i = 0; i < json.size() && deepest <= limit; ++i) {
        const char c = json[i];
        if (c == '"') {
            for (++i; i < json.size() && json[i] != '"'; ++i)
                if (json[i] == '\\') ++i;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return deepest;
}

/// Assimp's glTF readers parse the JSON recursively (a deep enough nesting overflows the
/// stack) and allocate a GLB chunk's claimed length before reading it. So the GLB framing must
/// match the file (glTF 2: a 12-byte header with the file's length, then chunks that fit) and
/// the JSON must nest at most kMaxJsonNesting levels.
void check_gltf(const std::string& where, const std::string& bytes, bool binary) {
    std::string_view json = bytes;
    if (binary) {
        const auto fail = [&](const std::string& why) { malformed(where, "GLB", why); };
        const auto word = [&](size_t at) {
            uint32_t value = 0;
            for (int b = 0; b < 4; ++b)
                value |= uint32_t(static_cast<unsigned char>(bytes[at + b])) << (8 * b);
            return value;
        };
        if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) fail("no glTF header");
        if (word(4) != 2) fail(fmt::format("version {}; tpsim reads glTF 2", word(4)));
        if (word(8) != bytes.size())
            fail(fmt::format("the header says {} bytes, the file has {}", word(8), bytes.size()));
        for (size_t at = 12; at < bytes.size();) {
            if (bytes.size() - at < 8) fail("a chunk header is cut off");
            const uint32_t length = word(at);
            if (length > bytes.size() - at - 8)
                fail(fmt::format("a chunk of {} bytes at byte {} runs past the end", length, at));
            if (at == 12) {
                if (bytes.compare(16, 4, "JSON") != 0) fail("the first chunk is not JSON");
                json = std::string_view(bytes).substr(20, length);
            }
            at += 8 + size_t(length);
        }
    }
    if (json_nesting(json, kMaxJsonNesting) > kMaxJsonNesting)
        malformed(where, "glTF",
                  fmt::format("its JSON nests more than {} levels deep", kMaxJsonNesting));
}

}  // namespace

bool is_mesh_file(const std::filesystem::path& path) {
    const std::string extension = lower_extension(path);
    return std::find(std::begin(kMeshFormats), std::end(kMeshFormats), extension) !=
           std::end(kMeshFormats);
}

std::string_view mesh_format_list() {
    return kMeshFormatList;
}

ImportedMesh import_mesh(const std::filesystem::path& path) {
    const std::string where = path.string();
    std::error_code error;
    if (!std::filesystem::exists(path, error))
        throw Error(fmt::format("{}: mesh file not found (paths in scene files are relative to "
                                "the scene file)",
                                where));
    if (!is_mesh_file(path))
        throw Error(fmt::format("{}: '{}' is not a mesh format tpsim reads; use {} (convert "
                                "other formats, e.g. with Blender)",
                                where, path.extension().string(), kMeshFormatList));
    const std::string extension = lower_extension(path);
    const std::string bytes = read_input_file(path, "mesh", kMaxMeshFileBytes);
    if (extension == ".ply") check_ply(where, bytes);
    if (extension == ".off") check_off(where, bytes);
    if (extension == ".gltf" || extension == ".glb") check_gltf(where, bytes, extension == ".glb");
    static const MeshReader& reader =
        load_module<MeshReader>(kMeshReaderModule, kMeshReaderEntry, "the mesh module (assimp)");
    // Every file the mesh names (an OBJ's material library, a glTF's buffers) is read through
    // the same input check as the mesh itself.
    return reader.read(where, extension, bytes, [&](const std::string& file) {
        return read_input_file(file, fmt::format("file named by mesh {}", where),
                               kMaxMeshFileBytes);
    });
}

}  // namespace tpsim::scene
