// The text screen of scene files (scene_screen_pvt.h): nesting depth by a streaming scan of the bytes,
// then glTF's node tree from its JSON, parsed only once the nesting is known to be shallow.
#include "scene_screen_pvt.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "conus/core/error.h"
#include "extension_pvt.h"

namespace conus::sceneio {
namespace {

// Bytes of a file in order, through a buffer; -1 at the end.
class Bytes {
public:
    Bytes(const std::string& path, std::uint64_t from, std::uint64_t count)
        : m_file(std::fopen(path.c_str(), "rb")), m_left(count) {
        if (m_file && from > 0 && std::fseek(m_file, static_cast<long>(from), SEEK_SET) != 0) m_left = 0;
    }
    ~Bytes() {
        if (m_file) std::fclose(m_file);
    }
    Bytes(const Bytes&) = delete;
    Bytes& operator=(const Bytes&) = delete;
    bool ok() const { return m_file != nullptr; }
    int next() {
        if (m_at == m_end) {
            if (!m_file || m_left == 0) return -1;
            const std::size_t n = std::fread(m_buffer, 1, std::min<std::uint64_t>(sizeof m_buffer, m_left), m_file);
            if (n == 0) return -1;
            m_left -= n;
            m_at = 0;
            m_end = n;
        }
        return m_buffer[m_at++];
    }

private:
    std::FILE* m_file;
    std::uint64_t m_left;
    unsigned char m_buffer[1 << 16];
    std::size_t m_at = 0, m_end = 0;
};

[[noreturn]] void tooDeep(const std::string& what, const char* kind, int limit) {
    throw Error(ErrorCode::LimitExceeded, what + ": its " + kind + " nests more than " + std::to_string(limit) +
                                              " levels deep, the limit");
}

// JSON: arrays and objects outside strings.
void checkJsonDepth(Bytes& in, int limit, const std::string& what) {
    int depth = 0;
    bool string = false;
    for (int c; (c = in.next()) >= 0;) {
        if (string) {
            if (c == '\\') in.next();
            else if (c == '"') string = false;
        } else if (c == '"') {
            string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > limit) tooDeep(what, "JSON", limit);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
}

// An XML element's tag as the scan below sees it: its name and (for start tags) the text of its
// attributes, each cut at kMaxTagText characters.
struct XmlTag {
    std::string name, attributes;
    bool end = false, empty = false;  // </name>, <name ... />
};
constexpr std::size_t kMaxTagText = 4096;

// The value of attribute `key` in a tag's attribute text, or "".
std::string attribute(const std::string& attributes, const char* key) {
    const std::string k = key;
    for (std::size_t at = 0; (at = attributes.find(k, at)) != std::string::npos; at += k.size()) {
        if (at > 0 && !std::isspace(static_cast<unsigned char>(attributes[at - 1]))) continue;
        std::size_t i = at + k.size();
        while (i < attributes.size() && std::isspace(static_cast<unsigned char>(attributes[i]))) ++i;
        if (i >= attributes.size() || attributes[i] != '=') continue;
        ++i;
        while (i < attributes.size() && std::isspace(static_cast<unsigned char>(attributes[i]))) ++i;
        if (i >= attributes.size() || (attributes[i] != '"' && attributes[i] != '\'')) continue;
        const std::size_t close = attributes.find(attributes[i], i + 1);
        return close == std::string::npos ? std::string() : attributes.substr(i + 1, close - i - 1);
    }
    return {};
}

// XML: elements opened and not yet closed (comments, declarations and processing instructions
// skipped; quoted attribute values may hold '>'), each tag given to `onTag`, each character of
// text between tags (CDATA sections' whole, "[CDATA[" included) to `onText`.
template <class OnTag, class OnText>
void scanXml(Bytes& in, int limit, const std::string& what, OnTag onTag, OnText onText) {
    int depth = 0;
    const auto skipPast = [&](const char* end) {  // to the end of `end`
        const std::size_t n = std::strlen(end);
        std::size_t matched = 0;
        for (int c; matched < n && (c = in.next()) >= 0;)
            matched = c == end[matched] ? matched + 1 : (c == end[0] ? 1 : 0);
    };
    XmlTag tag;
    for (int c = in.next(); c >= 0;) {
        if (c != '<') {
            onText(c);
            c = in.next();
            continue;
        }
        c = in.next();
        if (c == '?') {
            skipPast("?>");
        } else if (c == '!') {
            const int a = in.next(), b = in.next();
            if (a == '-' && b == '-') {
                skipPast("-->");
            } else if (a == '[') {  // CDATA: text as it stands
                onText(a);
                onText(b);
                std::size_t matched = 0;
                for (int t; matched < 3 && (t = in.next()) >= 0;) {
                    onText(t);
                    matched = t == "]]>"[matched] ? matched + 1 : (t == ']' ? 1 : 0);
                }
            } else {
                skipPast(">");
            }
        } else {
            // A tag: to its '>', quoted values skipped; "/>" closes it at once.
            tag = XmlTag{};
            tag.end = c == '/';
            if (tag.end) c = in.next();
            int quote = 0, last = 0;
            bool inName = true;
            for (; c >= 0; last = c, c = in.next()) {
                if (quote) {
                    if (c == quote) quote = 0;
                } else if (c == '"' || c == '\'') {
                    quote = c;
                } else if (c == '>') {
                    break;
                }
                if (inName && (std::isspace(c) || c == '/' || quote)) inName = false;
                std::string& text = inName ? tag.name : tag.attributes;
                if (text.size() < kMaxTagText) text += static_cast<char>(c);
            }
            tag.empty = !tag.end && last == '/';
            if (tag.end) {
                if (depth > 0) --depth;
            } else if (!tag.empty && ++depth > limit) {
                tooDeep(what, "XML", limit);
            }
            if (const std::size_t colon = tag.name.find(':'); colon != std::string::npos) tag.name.erase(0, colon + 1);
            onTag(tag);
        }
        c = in.next();
    }
}

std::int64_t saturated(std::int64_t a, std::int64_t b, std::int64_t cap) { return std::min(cap, a + b); }

// A node graph: nodes with their own triangles and children (by index), counted from the roots
// with every shared node expanded once per path to it (memoized, so the count costs one visit a
// node), refused past the caps or on a cycle.
class NodeGraph {
public:
    NodeGraph(const SceneCaps& caps, const std::string& what) : m_caps(caps), m_what(what) {}

    std::vector<std::vector<std::int64_t>> children;
    std::vector<std::int64_t> triangles;
    std::vector<std::int64_t> roots;

    std::int64_t add() {
        children.emplace_back();
        triangles.push_back(0);
        return std::int64_t(children.size()) - 1;
    }

    void check() {
        m_visits.assign(children.size(), Visit{});
        std::int64_t nodes = 0, total = 0;
        for (const std::int64_t root : roots) {
            const Visit& v = visit(root, 1);
            nodes = saturated(nodes, v.nodes, m_caps.maxNodes + 1);
            total = saturated(total, v.triangles, m_caps.maxTriangles + 1);
        }
        if (nodes > m_caps.maxNodes)
            throw Error(ErrorCode::LimitExceeded, m_what + ": its node tree expands to more than " +
                                                      std::to_string(m_caps.maxNodes) +
                                                      " nodes, the limit (each shared node counts once per path to it)");
        if (total > m_caps.maxTriangles)
            throw Error(ErrorCode::LimitExceeded, m_what + ": its nodes instance more than " +
                                                      std::to_string(m_caps.maxTriangles) +
                                                      " triangles, the limit (counted before any instance is expanded)");
    }

private:
    struct Visit {
        int state = 0;  // 0 not seen, 1 on the current path, 2 counted
        std::int64_t nodes = 0, triangles = 0;
    };

    // The recursion ends at the depth limit, so it never goes deeper than that.
    const Visit& visit(std::int64_t node, int level) {
        static const Visit kNone;
        if (node < 0 || node >= std::int64_t(children.size())) return kNone;  // the library refuses it
        if (level > m_caps.maxDepth)
            throw Error(ErrorCode::LimitExceeded, m_what + ": its node tree is more than " + std::to_string(m_caps.maxDepth) +
                                                      " nodes deep, the limit");
        if (m_visits[std::size_t(node)].state == 2) return m_visits[std::size_t(node)];
        if (m_visits[std::size_t(node)].state == 1)
            throw Error(ErrorCode::Corrupt, m_what + ": node " + std::to_string(node) + " is its own ancestor (a cycle)");
        m_visits[std::size_t(node)].state = 1;
        std::int64_t nodes = 1, total = std::min(triangles[std::size_t(node)], m_caps.maxTriangles + 1);
        for (const std::int64_t child : children[std::size_t(node)]) {
            const Visit& c = visit(child, level + 1);
            nodes = saturated(nodes, c.nodes, m_caps.maxNodes + 1);
            total = saturated(total, c.triangles, m_caps.maxTriangles + 1);
        }
        m_visits[std::size_t(node)] = {2, nodes, total};
        return m_visits[std::size_t(node)];
    }

    const SceneCaps& m_caps;
    const std::string& m_what;
    std::vector<Visit> m_visits;
};

// COLLADA's node graph: <node>s nested in each other and naming others by <instance_node
// url="#id"> (Assimp copies a node once per instance while it imports), their geometry by
// <instance_geometry url="#id">, each geometry's primitives by their count attributes. The roots
// are the nodes of the visual scenes.
class ColladaGraph {
public:
    ColladaGraph(const SceneCaps& caps, const std::string& what) : m_graph(caps, what), m_what(what) {}

    void onTag(const XmlTag& tag) {
        const std::string& name = tag.name;
        if (name == "COLLADA") m_collada = true;
        // A primitive's index list: Assimp's reader reads it number by number and, at a character
        // that is neither a digit nor a space, neither moves on nor stops (a 9.7 KB file grew
        // past 4.7 GB in 15 s), so every such character is refused before it reads.
        if (name == "p" || name == "ph" || name == "h") m_indexList = m_collada && !tag.end && !tag.empty;
        if (name == "visual_scene") m_inScene = !tag.end && !tag.empty;
        if (name == "geometry") m_geometry = tag.end || tag.empty ? std::string() : attribute(tag.attributes, "id");
        if (tag.end) {
            if (name == "node" && !m_open.empty()) m_open.pop_back();
            return;
        }
        if (name == "node") {
            const std::int64_t node = m_graph.add();
            if (!m_open.empty()) m_graph.children[std::size_t(m_open.back())].push_back(node);
            else if (m_inScene) m_graph.roots.push_back(node);
            if (const std::string id = attribute(tag.attributes, "id"); !id.empty()) m_ids.emplace(id, node);
            if (!tag.empty) m_open.push_back(node);
        } else if (name == "instance_node" && !m_open.empty()) {
            m_nodeRefs.emplace_back(m_open.back(), attribute(tag.attributes, "url"));
        } else if (name == "instance_geometry" && !m_open.empty()) {
            m_geometryRefs.emplace_back(m_open.back(), attribute(tag.attributes, "url"));
        } else if (!m_geometry.empty() && (name == "triangles" || name == "polylist" || name == "polygons" ||
                                           name == "tristrips" || name == "trifans")) {
            const std::string count = attribute(tag.attributes, "count");
            std::int64_t n = 0;
            for (char c : count.substr(0, 12))
                if (c >= '0' && c <= '9') n = n * 10 + (c - '0');
            std::int64_t& sum = m_geometryTriangles[m_geometry];
            sum = std::min<std::int64_t>(sum + n, std::int64_t{1} << 40);
        }
    }

    void onText(int c) {
        if (!m_indexList || (c >= '0' && c <= '9') || c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f') return;
        throw Error(ErrorCode::Corrupt, m_what + ": a COLLADA index list (<p>) holds a character that is neither a digit nor a "
                                                 "space, which the library's reader would loop on without end");
    }

    void check() {
        if (!m_collada) return;
        const auto target = [](const std::string& url) { return url.empty() || url[0] != '#' ? url : url.substr(1); };
        for (const auto& [node, url] : m_nodeRefs)
            if (const auto it = m_ids.find(target(url)); it != m_ids.end())
                m_graph.children[std::size_t(node)].push_back(it->second);
        for (const auto& [node, url] : m_geometryRefs)
            if (const auto it = m_geometryTriangles.find(target(url)); it != m_geometryTriangles.end())
                m_graph.triangles[std::size_t(node)] = std::min<std::int64_t>(
                    m_graph.triangles[std::size_t(node)] + it->second, std::int64_t{1} << 40);
        m_graph.check();
    }

private:
    NodeGraph m_graph;
    const std::string& m_what;
    bool m_collada = false, m_inScene = false, m_indexList = false;
    std::string m_geometry;
    std::vector<std::int64_t> m_open;
    std::map<std::string, std::int64_t> m_ids;
    std::map<std::string, std::int64_t> m_geometryTriangles;
    std::vector<std::pair<std::int64_t, std::string>> m_nodeRefs, m_geometryRefs;
};

// ---- glTF's node tree --------------------------------------------------------------------------

// An integer member of `object`, or -1 (Assimp refuses what is not one).
std::int64_t index(const nlohmann::json& object, const char* key) {
    if (!object.is_object()) return -1;
    const auto it = object.find(key);
    return it != object.end() && it->is_number_integer() ? it->get<std::int64_t>() : -1;
}

// The triangles of one glTF mesh: each triangle-list, strip or fan primitive's corners (its
// indices, else its positions) as its accessor counts them.
std::int64_t meshTriangles(const nlohmann::json& mesh, const nlohmann::json* accessors, std::int64_t cap) {
    std::int64_t total = 0;
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) return 0;
    for (const nlohmann::json& p : mesh["primitives"]) {
        if (!p.is_object()) continue;
        std::int64_t accessor = index(p, "indices");
        if (accessor < 0 && p.contains("attributes")) accessor = index(p["attributes"], "POSITION");
        if (!accessors || accessor < 0 || accessor >= std::int64_t(accessors->size())) continue;
        const std::int64_t count = std::max<std::int64_t>(0, index((*accessors)[std::size_t(accessor)], "count"));
        const std::int64_t mode = p.contains("mode") ? index(p, "mode") : 4;
        const std::int64_t t = mode == 4 ? count / 3 : mode == 5 || mode == 6 ? std::max<std::int64_t>(0, count - 2) : 0;
        total = saturated(total, t, cap);
    }
    return total;
}

// A glTF's node graph: its nodes, their meshes' triangles and children; the roots are the nodes of
// the scene Assimp imports (the document's `scene`, else the first; with no scenes, every node).
void checkGltfGraph(const nlohmann::json& doc, const SceneCaps& caps, const std::string& what) {
    const auto array = [&](const char* key) {
        const auto it = doc.find(key);
        return it != doc.end() && it->is_array() ? &*it : nullptr;
    };
    const nlohmann::json* nodes = array("nodes");
    if (!nodes) return;
    std::vector<std::int64_t> meshes;
    if (const nlohmann::json* list = array("meshes"))
        for (const nlohmann::json& mesh : *list) meshes.push_back(meshTriangles(mesh, array("accessors"), caps.maxTriangles + 1));
    NodeGraph graph(caps, what);
    for (const nlohmann::json& n : *nodes) {
        const std::int64_t node = graph.add();
        const std::int64_t mesh = index(n, "mesh");
        if (mesh >= 0 && mesh < std::int64_t(meshes.size())) graph.triangles[std::size_t(node)] = meshes[std::size_t(mesh)];
        if (n.is_object() && n.contains("children") && n["children"].is_array())
            for (const nlohmann::json& child : n["children"])
                if (child.is_number_integer()) graph.children[std::size_t(node)].push_back(child.get<std::int64_t>());
    }
    const nlohmann::json* scenes = array("scenes");
    if (scenes && !scenes->empty()) {
        std::int64_t chosen = index(doc, "scene");
        if (chosen < 0 || chosen >= std::int64_t(scenes->size())) chosen = 0;
        const nlohmann::json& scene = (*scenes)[std::size_t(chosen)];
        if (scene.is_object() && scene.contains("nodes") && scene["nodes"].is_array())
            for (const nlohmann::json& n : scene["nodes"])
                if (n.is_number_integer()) graph.roots.push_back(n.get<std::int64_t>());
    } else {
        for (std::size_t n = 0; n < nodes->size(); ++n) graph.roots.push_back(std::int64_t(n));
    }
    graph.check();
}

std::string readRange(const std::string& path, std::uint64_t from, std::uint64_t count) {
    std::string text;
    Bytes in(path, from, count);
    text.reserve(static_cast<std::size_t>(count));
    for (int c; (c = in.next()) >= 0;) text += static_cast<char>(c);
    return text;
}

void checkGltfTree(const std::string& json, const SceneCaps& caps, const std::string& what) {
    // Only the structure is kept: buffers, images and other large members are dropped as parsed.
    static const std::set<std::string> kKept = {"nodes", "meshes", "accessors", "scenes", "scene"};
    const nlohmann::json::parser_callback_t keep = [](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        return !(depth == 1 && event == nlohmann::json::parse_event_t::key && !kKept.count(parsed.get<std::string>()));
    };
    const nlohmann::json doc = nlohmann::json::parse(json, keep, /*allow_exceptions=*/false);
    // Refused rather than left to Assimp: its JSON reader takes text this one does not (invalid
    // UTF-8 in a key), and a node graph not screened here may instance past every cap.
    if (!doc.is_object()) throw Error(ErrorCode::Corrupt, what + ": its JSON does not parse as a glTF's (UTF-8 JSON, an object)");
    checkGltfGraph(doc, caps, what);
}

}  // namespace

void screenSceneText(const std::string& path, std::uintmax_t bytes, const SceneCaps& caps, const std::string& what) {
    unsigned char head[20] = {};
    std::uint64_t jsonFrom = 0, jsonBytes = bytes;
    {
        Bytes in(path, 0, sizeof head);
        for (std::size_t i = 0; i < sizeof head; ++i) {
            const int c = in.next();
            if (c < 0) break;
            head[i] = static_cast<unsigned char>(c);
        }
    }
    const std::string ext = lowerExtension(path);
    bool json = false, xml = false;
    if (std::memcmp(head, "glTF", 4) == 0) {  // a binary glTF: its first chunk is the JSON
        const auto u32 = [&](int at) {
            return std::uint64_t(head[at]) | std::uint64_t(head[at + 1]) << 8 | std::uint64_t(head[at + 2]) << 16 |
                   std::uint64_t(head[at + 3]) << 24;
        };
        if (bytes < 20 || std::memcmp(head + 16, "JSON", 4) != 0) return;  // Assimp refuses it
        jsonFrom = 20;
        jsonBytes = std::min<std::uint64_t>(u32(12), bytes - 20);
        json = true;
    } else {
        std::size_t at = std::memcmp(head, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;  // a UTF-8 byte order mark
        while (at < sizeof head && std::isspace(head[at])) ++at;
        json = at < sizeof head && (head[at] == '{' || head[at] == '[');
        xml = at < sizeof head && head[at] == '<';
        json = json || ext == ".gltf";
    }
    if (!json && !xml) return;
    {
        Bytes in(path, jsonFrom, jsonBytes);
        if (!in.ok()) return;
        if (json) {
            checkJsonDepth(in, caps.maxMarkupDepth, what);
        } else {
            ColladaGraph collada(caps, what);
            scanXml(in, caps.maxMarkupDepth, what, [&](const XmlTag& tag) { collada.onTag(tag); }, [&](int c) { collada.onText(c); });
            collada.check();
        }
    }
    if (json && (ext == ".gltf" || ext == ".glb" || std::memcmp(head, "glTF", 4) == 0))
        checkGltfTree(readRange(path, jsonFrom, jsonBytes), caps, what);
}

}  // namespace conus::sceneio
