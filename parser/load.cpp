#include "parser/load.h"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>

#include "parser/classic.h"
#include "parser/vrml1.h"
#include "parser/x3d_xml.h"

namespace vr {

namespace fs = std::filesystem;

std::string_view encoding_name(Encoding e) {
    switch (e) {
        case Encoding::Vrml97:
            return "VRML97 (classic)";
        case Encoding::X3dClassic:
            return "X3D classic";
        case Encoding::X3dXml:
            return "X3D XML";
        case Encoding::Vrml1:
            return "VRML 1.0";
        case Encoding::Unknown:
            return "unknown";
    }
    return "unknown";
}

// Decompresses a whole gzip stream into one string, written in place (no staging buffer, no copy
// per chunk). The stream's trailer gives the size modulo 2^32; it sizes the string when it is
// plausible (a deflate stream expands at most about 1032 times), so a 100 MB scene is not grown,
// and copied, by doubling.
static std::string gunzip(std::string_view data, size_t max_bytes) {
    z_stream zs{};
    if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK)
        throw std::runtime_error("cannot start gzip decompression");
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    zs.avail_in = static_cast<uInt>(data.size());
    size_t hint = size_t(1) << 16;
    if (data.size() >= 18) {
        const auto* t = reinterpret_cast<const unsigned char*>(data.data() + data.size() - 4);
        const size_t isize =
            size_t(t[0]) | size_t(t[1]) << 8 | size_t(t[2]) << 16 | size_t(t[3]) << 24;
        if (isize <= data.size() * 1032)
            hint = std::max(hint, isize + 1);  // +1: the end shows without growing
    }
    std::string out(std::min(hint, max_bytes + 1), '\0');
    size_t used = 0;
    int ret = Z_OK;
    do {
        if (used == out.size()) out.resize(std::min(out.size() * 2, max_bytes + 1));
        const size_t room = std::min<size_t>(out.size() - used, size_t(1) << 30);
        zs.next_out = reinterpret_cast<Bytef*>(out.data() + used);
        zs.avail_out = static_cast<uInt>(room);
        ret = inflate(&zs, Z_NO_FLUSH);
        if (ret != Z_OK && ret != Z_STREAM_END && ret != Z_BUF_ERROR) {
            inflateEnd(&zs);
            throw std::runtime_error("gzip data is corrupt");
        }
        used += room - zs.avail_out;
        if (used > max_bytes) {
            inflateEnd(&zs);
            throw std::runtime_error("decompressed size exceeds the limit of " +
                                     std::to_string(max_bytes) + " bytes");
        }
        // No input left and output space unused: the stream stopped before its end.
        if (ret == Z_BUF_ERROR || (zs.avail_in == 0 && zs.avail_out != 0)) break;
    } while (ret != Z_STREAM_END);
    if (ret != Z_STREAM_END) {
        inflateEnd(&zs);
        throw std::runtime_error(
            "gzip data is truncated (the file ends before the compressed stream does)");
    }
    inflateEnd(&zs);
    out.resize(used);
    return out;
}

static bool is_gzip(std::string_view data) {
    return data.size() >= 2 && static_cast<unsigned char>(data[0]) == 0x1f &&
           static_cast<unsigned char>(data[1]) == 0x8b;
}

std::string read_file_bytes(const fs::path& path, size_t max_bytes) {
    max_bytes = std::min<size_t>(max_bytes, kMaxSourceBytes);  // the offsets a place can hold
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw std::runtime_error("is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open file: " + std::string(std::strerror(errno)));
    in.seekg(0, std::ios::end);
    std::streamoff size = in.tellg();
    if (size < 0) throw std::runtime_error("cannot read file");
    if (static_cast<uint64_t>(size) > max_bytes)
        throw std::runtime_error("file is larger than the limit of " + std::to_string(max_bytes) +
                                 " bytes");
    in.seekg(0);
    std::string data(static_cast<size_t>(size), '\0');
    in.read(data.data(), size);
    if (!in) throw std::runtime_error("cannot read file");
    if (is_gzip(data)) return gunzip(data, max_bytes);
    return data;
}

SourceText read_source_text(const fs::path& path, size_t max_bytes) {
    // Plain regular files of a megabyte or more are mapped; gzip is decompressed straight from the
    // mapping. Anything else (small files, pipes, devices, a failed mapping) is read by
    // read_file_bytes.
    constexpr size_t kMapFrom = size_t(1) << 20;
    max_bytes = std::min<size_t>(max_bytes, kMaxSourceBytes);  // the offsets a place can hold
    struct stat st {};
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
        static_cast<uint64_t>(st.st_size) >= kMapFrom &&
        static_cast<uint64_t>(st.st_size) <= max_bytes) {
        SourceText mapped = SourceText::map(fd, static_cast<size_t>(st.st_size));
        ::close(fd);
        if (mapped.mapped()) {
            if (!is_gzip(mapped.view())) return mapped;
            return SourceText(gunzip(mapped.view(), max_bytes));
        }
        return SourceText(read_file_bytes(path, max_bytes));
    }
    if (fd >= 0) ::close(fd);
    return SourceText(read_file_bytes(path, max_bytes));
}

// The first line as it can be shown in a message: non-printable bytes as \xNN.
static std::string printable(std::string_view s) {
    std::string out;
    for (unsigned char c : s) {
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02X", c);
            out += buf;
        }
    }
    return out;
}

// The words of a classic header line, "#VRML V2.0 utf8 [comment]", which exporters write with
// runs of spaces or tabs between them (browsers read those too). Empty words when the line does
// not start with "#VRML" or "#X3D" and white space.
struct HeaderWords {
    std::string shown;  // the line as a message shows it
    std::string_view tag, version, encoding;
};

static HeaderWords header_words(std::string_view text) {
    HeaderWords h;
    const size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // UTF-8 byte order mark
    const size_t end = std::min(text.find_first_of("\r\n", start), text.size());
    const std::string_view line = text.substr(start, end - start);
    h.shown = printable(line.substr(0, 60));
    std::string_view words[3];
    size_t p = 0;
    for (std::string_view& w : words) {
        p = std::min(line.find_first_not_of(" \t", p), line.size());
        const size_t q = std::min(line.find_first_of(" \t", p), line.size());
        w = line.substr(p, q - p);
        p = q;
    }
    if (words[0] != "#VRML" && words[0] != "#X3D") return h;
    h.tag = words[0];
    h.version = words[1];
    h.encoding = words[2];
    return h;
}

static Encoding detect_encoding(std::string_view text, HeaderWords& header) {
    header = header_words(text);
    const std::string_view v = header.version;
    if (header.tag == "#VRML" && v == "V2.0") return Encoding::Vrml97;
    if (header.tag == "#VRML" && v == "V1.0") return Encoding::Vrml1;
    // "#X3D V2.0" names no X3D version; Titania's tests hold one such file, read as X3D 3 (warned).
    if (header.tag == "#X3D" && (v.starts_with("V3.") || v.starts_with("V4.") || v == "V2.0"))
        return Encoding::X3dClassic;
    const size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    size_t p = text.find_first_not_of(" \t\r\n", start);
    if (p != std::string::npos && text.compare(p, 1, "<") == 0) return Encoding::X3dXml;
    return Encoding::Unknown;
}

// The X3D major version a file's header states: "#X3D V4.0 utf8" or the version attribute of the
// <X3D> element (after any XML declaration, DOCTYPE and comments, within the first 64 KiB); 0 for
// VRML and for a header without a version.
int x3d_major_version(std::string_view text) {
    auto digit_at = [&](size_t i) {
        return i < text.size() && text[i] >= '0' && text[i] <= '9' ? text[i] - '0' : 0;
    };
    if (const HeaderWords h = header_words(text); h.tag == "#X3D")
        return h.version == "V2.0" ? 3 : digit_at(size_t(h.version.data() - text.data()) + 1);
    const std::string_view head = text.substr(0, 1 << 16);
    size_t tag = head.find("<X3D");
    while (tag != std::string_view::npos && tag + 4 < head.size() &&
           std::isalnum(static_cast<unsigned char>(head[tag + 4])))
        tag = head.find("<X3D", tag + 4);  // <X3DSomething> is another element
    if (tag == std::string_view::npos) return 0;
    const size_t close = head.find('>', tag);
    const std::string_view element = head.substr(tag, close - tag);
    for (size_t v = element.find("version"); v != std::string_view::npos;
         v = element.find("version", v + 7)) {
        size_t i = element.find_first_not_of(" \t\r\n", v + 7);
        if (i == std::string_view::npos || element[i] != '=') continue;
        i = element.find_first_not_of(" \t\r\n", i + 1);
        if (i == std::string_view::npos || (element[i] != '\'' && element[i] != '"')) continue;
        return digit_at(size_t(element.data() - text.data()) + i + 1);
    }
    return 0;
}

static bool is_under(const fs::path& path, const fs::path& root) {
    auto r = root.begin(), p = path.begin();
    for (; r != root.end(); ++r, ++p) {
        if (r->empty()) continue;  // trailing separator
        if (p == path.end() || *p != *r) return false;
    }
    return true;
}

static std::string percent_decode(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size() &&
            std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
            std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
            out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += s[i];
        }
    }
    return out;
}

// "file:///a/b", "file://localhost/a/b", "file:/a/b", "file:a/b" -> the path; "file://host/a" names
// another machine and gives nothing.
static std::optional<std::string> file_url_path(const std::string& url, const std::string& lower) {
    if (lower.rfind("file://", 0) != 0) return url.substr(5);
    const std::string rest = url.substr(7);
    const size_t slash = rest.find('/');
    const std::string host = lower.substr(7, slash);
    if (host.empty() || slash == std::string::npos)
        return rest;  // "file://x.jpg": a sloppy relative URL
    if (host == "localhost") return rest.substr(slash);
    return std::nullopt;
}

fs::path resolve_url(const std::string& url_in, const fs::path& from_file,
                     const std::vector<fs::path>& allowed_roots, std::string& why) {
    std::string url = url_in;
    while (!url.empty() && std::isspace(static_cast<unsigned char>(url.back()))) url.pop_back();
    while (!url.empty() && std::isspace(static_cast<unsigned char>(url.front())))
        url.erase(url.begin());
    if (url.empty()) {
        why = "empty URL";
        return {};
    }
    std::string lower = url;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (lower.rfind("file:", 0) == 0) {
        std::optional<std::string> local = file_url_path(url, lower);
        if (!local) {
            why = "'" + url_in + "' names a file on another machine; it is never fetched";
            return {};
        }
        url = *local;
    } else {
        size_t colon = url.find(':');
        size_t slash = url.find('/');
        // "C:/..." is a drive letter, not a scheme; anything else before ':' is a scheme.
        if (colon != std::string::npos && colon > 1 &&
            (slash == std::string::npos || colon < slash)) {
            why = "network or non-file URL '" + url_in + "' is never fetched";
            return {};
        }
    }
    url = percent_decode(url);
    fs::path candidate =
        fs::path(url).is_absolute() ? fs::path(url) : from_file.parent_path() / url;
    std::error_code ec;
    candidate =
        fs::absolute(candidate, ec);  // a relative main file name must not make this relative
    fs::path canonical = fs::weakly_canonical(candidate, ec);
    if (ec) canonical = candidate.lexically_normal();
    const bool allowed =
        allowed_roots.empty() ||
        std::any_of(allowed_roots.begin(), allowed_roots.end(),
                    [&](const fs::path& root) { return is_under(canonical, root); });
    if (!allowed) {
        why = "'" + url_in + "' lies outside the --sandbox folder " +
              allowed_roots.front().string() + " (--allow-path DIR lets URLs reach DIR too)";
        return {};
    }
    if (!fs::is_regular_file(canonical, ec)) {
        why = "file '" + url_in + "' not found";
        return {};
    }
    return canonical;
}

fs::path resolve_or_note(const std::string& url, const fs::path& from_file,
                         const std::vector<fs::path>& allowed_roots, UrlFailures& failures,
                         bool name_url) {
    std::string why;
    fs::path path = resolve_url(url, from_file, allowed_roots, why);
    if (path.empty()) failures.add(name_url ? url + ": " + why : why);
    return path;
}

namespace {

Spec spec_of(Encoding e) {
    switch (e) {
        case Encoding::X3dClassic:
        case Encoding::X3dXml:
            return Spec::X3d;
        case Encoding::Vrml1:
            return Spec::Vrml1;
        default:
            return Spec::Vrml97;
    }
}

// Reads the main file and, recursively, what its Inline and EXTERNPROTO URLs name.
class Loader {
  public:
    Loader(LoadedScene& scene, const LoadOptions& options) : scene_(scene), options_(options) {}

    // The main file counts as being read, so that an Inline leading back to it is a cycle.
    void enter_main_file(const fs::path& path) {
        std::error_code ec;
        stack_.push_back(fs::weakly_canonical(fs::absolute(path, ec), ec).string());
    }

    // Reads one file's text (already added as source `file`); returns its top-level nodes.
    ClassicResult read_source(uint32_t file, size_t inline_depth) {
        const SourceFile& src = scene_.sources.file(file);
        HeaderWords header;
        Encoding enc = detect_encoding(src.text, header);
        if (file == 0) scene_.encoding = enc;
        if (scene_.x3d_major.size() <= file) scene_.x3d_major.resize(file + 1, 0);
        scene_.x3d_major[file] = uint8_t(x3d_major_version(src.text));
        ClassicResult result;
        const size_t first_node = scene_.tree.nodes.size();
        const size_t first_import = scene_.tree.imports.size(),
                     first_route = scene_.tree.routes.size();
        ExternProtoResolver resolver = [this, inline_depth](const std::vector<std::string>& urls,
                                                            uint32_t from, SourceLoc where,
                                                            Name name) {
            return resolve_externproto(urls, from, where, name, inline_depth);
        };
        switch (enc) {
            case Encoding::Vrml97:
            case Encoding::X3dClassic: {
                if (!check_header(file, header)) {
                    result.ok = false;
                    break;
                }
                // Only the main file's pieces are consumed: Inline contents stay nodes.
                result = read_classic(scene_, file, spec_of(enc), options_.limits, resolver,
                                      file == 0 ? options_.piece_consumer.get() : nullptr);
                break;
            }
            case Encoding::X3dXml:
                // libxml2 and the XML reader place elements by 32-bit offsets (x3d_xml_reader.h):
                // a larger file is refused, not misread.
                if (src.text.size() > UINT32_MAX) {
                    scene_.diagnostics.error(
                        {file, 0}, "an X3D XML file is read up to 4 GiB (this one has " +
                                       std::to_string(src.text.size()) +
                                       " bytes); the classic encoding is read to any size");
                    result.ok = false;
                    break;
                }
                result = read_x3d_xml(scene_, file, options_.limits, resolver,
                                      file == 0 ? options_.piece_consumer.get() : nullptr);
                break;
            case Encoding::Vrml1:
                result = read_vrml1(scene_, file, options_.limits);
                break;
            case Encoding::Unknown:
                // UTF-16 with a byte-order mark was converted (parser/utf16.h); without one,
                // '#' or '<' and a zero byte is all that shows it.
                if (src.text.starts_with(std::string_view("\xE0\0\0\x01", 4))) {
                    scene_.diagnostics.error(
                        {file, 0},
                        "the file is X3D's binary encoding (Fast Infoset, .x3db), which is not "
                        "read; convert it to X3D XML or classic encoding");
                    result.ok = false;
                    break;
                }
                if (src.text.size() >= 2 &&
                    ((src.text[1] == '\0' && (src.text[0] == '#' || src.text[0] == '<')) ||
                     (src.text[0] == '\0' && (src.text[1] == '#' || src.text[1] == '<')))) {
                    scene_.diagnostics.error(
                        {file, 0},
                        "the file looks UTF-16 encoded without a byte-order mark; save it as UTF-8 "
                        "or as UTF-16 with a byte-order mark");
                    result.ok = false;
                    break;
                }
                scene_.diagnostics.error(
                    {file, 0},
                    "not a VRML97 or X3D file: the first line is '" + header.shown +
                        "', expected '#VRML V2.0 utf8', '#X3D V3.x utf8' or an XML document");
                result.ok = false;
                break;
        }
        if (result.units.any()) apply_units(file, enc, header, first_node, result);
        // Inlines read below append their own imports and routes after this file's.
        const size_t end_import = scene_.tree.imports.size(), end_route = scene_.tree.routes.size();
        if (result.ok && options_.resolve_inlines)
            resolve_inlines(file, first_node, inline_depth, result.units.length);
        if (result.ok) resolve_imports(first_import, end_import, first_route, end_route);
        return result;
    }

  private:
    // Reads an Inline or EXTERNPROTO file: its errors become warnings of the including scene, which
    // still renders without it.
    ClassicResult read_demoting_errors(uint32_t file, size_t depth, const char* what) {
        Diagnostics outer;
        std::swap(outer, scene_.diagnostics);
        ClassicResult r = read_source(file, depth);
        std::swap(outer, scene_.diagnostics);
        for (const Diagnostic& d : outer.all()) {
            std::string message = d.severity == Severity::Error
                                      ? std::string(what) + " file not used: " + d.message
                                      : d.message;
            std::string cause = std::string(what) + ":" + std::to_string(d.loc.file) + ":" +
                                std::to_string(d.loc.offset) + ":" + d.message;
            for (uint32_t i = 0; i < d.count; ++i) {
                if (d.loc.valid())
                    scene_.diagnostics.warning(d.loc, message, cause);
                else
                    scene_.diagnostics.warning_in_file(d.file, message, cause);
            }
        }
        if (!r.ok) r.roots.clear();
        return r;
    }

    // "#VRML V2.0 utf8" / "#X3D V3.3 utf8"; exporters add text after utf8, which is allowed. A
    // header that names no encoding is not one (false, with an error).
    bool check_header(uint32_t file, const HeaderWords& header) {
        if (header.encoding.empty()) {
            scene_.diagnostics.error({file, 0}, "the header names no encoding: '" + header.shown +
                                                    "', expected '" + std::string(header.tag) +
                                                    " " + std::string(header.version) + " utf8'");
            return false;
        }
        if (header.encoding != "utf8")
            scene_.diagnostics.warning(
                {file, 0}, "header should say 'utf8' after the version: '" + header.shown + "'",
                "header-utf8");
        if (header.tag == "#X3D" && header.version == "V2.0")
            scene_.diagnostics.warning(
                {file, 0}, "the header names X3D V2.0, which does not exist; read as X3D 3",
                "header-x3d-v2");
        return true;
    }

    // UNIT statements (parser/units.h): allowed from X3D 3.3 on, but a file that has them means
    // them, so they are applied either way. Lengths are left to the scene build's scale.
    void apply_units(uint32_t file, Encoding enc, const HeaderWords& header, size_t first_node,
                     const ClassicResult& result) {
        std::string version;
        if (enc == Encoding::X3dXml) version = result.x3d_version;
        if (enc == Encoding::X3dClassic && header.version.size() > 1)
            version = header.version.substr(1);
        if (!units_allowed(version))
            scene_.diagnostics.warning(
                result.units.first,
                "UNIT statements need X3D 3.3 or later, and this file is " +
                    (version.empty() ? std::string(encoding_name(enc)) : "X3D " + version) +
                    "; its units are applied anyway",
                "unit-version");
        convert_angles(scene_.tree, file, first_node, result.units.angle);
    }

    void resolve_inlines(uint32_t file, size_t first_node, size_t depth, double length) {
        static const Name kInline = intern("Inline");
        static const Name kUrl = intern("url");
        static const Name kGeoLod = intern("GeoLOD");
        NodeTree& tree = scene_.tree;
        const size_t end = tree.nodes.size();
        for (size_t id = first_node; id < end; ++id) {
            if (tree.type(id) == kGeoLod) {
                resolve_geo_lod(static_cast<NodeId>(id), file, depth);
                continue;
            }
            if (tree.type(id) != kInline) continue;
            FieldView urls = tree.get(static_cast<NodeId>(id), kUrl);
            std::vector<std::string> list(urls.strings.begin(), urls.strings.end());
            if (list.empty()) continue;  // an Inline with no URL loads nothing, as specified
            SourceLoc where = tree.nodes[id].loc;
            auto loaded = load_inline(list, file, where, depth);
            if (!loaded) continue;
            tree.inline_roots[static_cast<NodeId>(id)] = loaded->roots;
            inline_file_[static_cast<NodeId>(id)] = loaded->file;
            if (loaded->length != length)
                tree.inline_length_scale[static_cast<NodeId>(id)] = loaded->length / length;
        }
    }

    // A GeoLOD (X3D 25.4.4) is drawn at its finer level, as a LOD's first level is: the top-level
    // nodes of the files child1Url to child4Url name, kept as the node's inline roots; when none
    // of them loads, its rootUrl's (a rootNode given in the file needs no loading).
    void resolve_geo_lod(NodeId id, uint32_t file, size_t depth) {
        NodeTree& tree = scene_.tree;
        const SourceLoc where = tree.nodes[id].loc;
        std::vector<NodeId> roots;
        auto load_field = [&](const char* field) {
            FieldView urls = tree.get(id, intern(field));
            std::vector<std::string> list(urls.strings.begin(), urls.strings.end());
            if (list.empty()) return;
            if (auto loaded = load_inline(list, file, where, depth))
                roots.insert(roots.end(), loaded->roots.begin(), loaded->roots.end());
        };
        for (const char* field : {"child1Url", "child2Url", "child3Url", "child4Url"})
            load_field(field);
        if (roots.empty() && tree.get(id, intern("rootNode")).nodes.empty()) load_field("rootUrl");
        if (!roots.empty()) tree.inline_roots[id] = std::move(roots);
    }

    // This file's IMPORTs [first, end) find their nodes among the EXPORTs of the file each Inline
    // read; the ROUTEs [first_route, end_route) naming them then connect those nodes. An unknown
    // export is an error at the IMPORT; an Inline not loaded drops its ROUTEs (it said why).
    void resolve_imports(size_t first, size_t end, size_t first_route, size_t end_route) {
        NodeTree& tree = scene_.tree;
        for (size_t i = first; i < end; ++i) {
            Import& imp = tree.imports[i];
            auto file = inline_file_.find(imp.inline_node);
            if (file == inline_file_.end()) continue;
            for (const Export& e : tree.exports)
                if (e.file == file->second && e.name == imp.exported) imp.node = e.node;
            if (imp.node == kNullNode)
                scene_.diagnostics.error(
                    imp.loc.get(), "IMPORT: the file of Inline '" +
                                       std::string(tree.def_name(imp.inline_node)) + "' (" +
                                       scene_.sources.file(file->second).path + ") exports no '" +
                                       std::string(name_text(imp.exported)) + "'");
        }
        size_t kept = first_route;
        for (size_t r = first_route; r < end_route; ++r) {
            Route& route = tree.routes[r];
            if (route.from_import != Route::kNoImport)
                route.from = tree.imports[route.from_import].node;
            if (route.to_import != Route::kNoImport) route.to = tree.imports[route.to_import].node;
            if (route.from != kNullNode && route.to != kNullNode) tree.routes[kept++] = route;
        }
        tree.routes.erase(tree.routes.begin() + static_cast<ptrdiff_t>(kept),
                          tree.routes.begin() + static_cast<ptrdiff_t>(end_route));
    }

    // An inlined file: its top-level nodes, its source, and metres per its length unit.
    struct InlineFile {
        std::vector<NodeId> roots;
        uint32_t file = 0;
        double length = 1.0;
    };

    std::optional<InlineFile> load_inline(const std::vector<std::string>& urls, uint32_t from,
                                          SourceLoc where, size_t depth) {
        UrlFailures failures;
        for (const std::string& url : urls) {
            const fs::path path = resolve_or_note(url, scene_.sources.file(from).path,
                                                  scene_.allowed_roots, failures);
            if (path.empty()) continue;
            std::string key = path.string();
            if (std::find(stack_.begin(), stack_.end(), key) != stack_.end()) {
                scene_.diagnostics.warning(
                    where, "Inline '" + url + "' includes itself (a cycle); skipped",
                    "inline-cycle:" + key);
                return std::nullopt;
            }
            auto cached = inline_cache_.find(key);
            if (cached != inline_cache_.end()) return cached->second;
            if (depth + 1 > options_.limits.max_inline_depth) {
                scene_.diagnostics.warning(where,
                                           "Inline nesting deeper than " +
                                               std::to_string(options_.limits.max_inline_depth) +
                                               " (limit); skipped",
                                           "inline-depth");
                return std::nullopt;
            }
            if (++inline_files_ > options_.limits.max_inline_files) {
                scene_.diagnostics.warning(where,
                                           "more than " +
                                               std::to_string(options_.limits.max_inline_files) +
                                               " Inline files (limit); skipped",
                                           "inline-count");
                return std::nullopt;
            }
            uint32_t file;
            try {
                file =
                    scene_.sources.add(key, read_source_text(path, options_.limits.max_file_bytes));
            } catch (const std::exception& e) {
                failures.add(key + ": " + e.what());
                continue;
            }
            ++scene_.stats.inline_files;
            stack_.push_back(key);
            ClassicResult r = read_demoting_errors(file, depth + 1, "Inline");
            stack_.pop_back();
            InlineFile loaded{std::move(r.roots), file, r.units.length};
            inline_cache_[key] = loaded;
            return loaded;
        }
        scene_.diagnostics.warning(where, "Inline not loaded: " + failures.message(),
                                   "inline-missing:" + failures.reasons);
        return std::nullopt;
    }

    std::shared_ptr<const ProtoDecl> resolve_externproto(const std::vector<std::string>& urls,
                                                         uint32_t from, SourceLoc where, Name name,
                                                         size_t depth) {
        UrlFailures failures;
        for (const std::string& full : urls) {
            // "urn:web3d:vrml97:node:Shape" / "urn:web3d:x3d:node:Shape" name a built-in node type.
            for (const char* prefix : {"urn:web3d:vrml97:node:", "urn:web3d:x3d:node:"}) {
                if (full.rfind(prefix, 0) != 0) continue;
                std::string type = full.substr(std::strlen(prefix));
                Spec spec = std::strstr(prefix, "x3d") ? Spec::X3d : Spec::Vrml97;
                if (const NodeTypeDecl* decl = Registry::builtin().lookup(spec, intern(type))) {
                    auto proto = std::make_shared<ProtoDecl>();
                    proto->name = name;
                    proto->builtin = decl;
                    return proto;
                }
            }
            std::string url = full, fragment;
            size_t hash = url.find('#');
            if (hash != std::string::npos) {
                fragment = url.substr(hash + 1);
                url = url.substr(0, hash);
            }
            if (url.empty())
                continue;  // "#Name" alone refers to this file: not supported by VRML97
            const fs::path path = resolve_or_note(url, scene_.sources.file(from).path,
                                                  scene_.allowed_roots, failures);
            if (path.empty()) continue;
            std::string key = path.string();
            std::shared_ptr<ProtoScope> scope;
            auto cached = proto_files_.find(key);
            if (cached != proto_files_.end()) {
                scope = cached->second;
            } else {
                if (std::find(stack_.begin(), stack_.end(), key) != stack_.end() ||
                    depth + 1 > options_.limits.max_inline_depth) {
                    failures.add(key + " refers back to itself");
                    continue;
                }
                uint32_t file;
                try {
                    file = scene_.sources.add(
                        key, read_source_text(path, options_.limits.max_file_bytes));
                } catch (const std::exception& e) {
                    failures.add(key + ": " + e.what());
                    continue;
                }
                stack_.push_back(key);
                // The PROTO file's own scene nodes are read but not part of the scene.
                ClassicResult r = read_demoting_errors(file, depth + 1, "EXTERNPROTO");
                stack_.pop_back();
                scope = r.protos ? r.protos : std::make_shared<ProtoScope>();
                proto_files_[key] = scope;
            }
            Name wanted = fragment.empty() ? name : intern(fragment);
            auto it = scope->protos.find(wanted);
            if (it == scope->protos.end() && fragment.empty() && !scope->order.empty())
                it = scope->protos.find(scope->order.front());
            if (it != scope->protos.end()) {
                const ProtoDecl* found = it->second.get();
                if (found->external) {
                    if (found->implementation) return found->implementation;
                    failures.add(key + " declares it as an EXTERNPROTO that is not resolved");
                    continue;
                }
                return it->second;
            }
            failures.add(key + " has no PROTO named '" +
                         (fragment.empty() ? std::string(name_text(name)) : fragment) + "'");
        }
        scene_.diagnostics.warning(
            where,
            "EXTERNPROTO " + std::string(name_text(name)) + " not resolved: " + failures.message(),
            "externproto:" + std::string(name_text(name)));
        return nullptr;
    }

    LoadedScene& scene_;
    const LoadOptions& options_;
    std::vector<std::string> stack_;  // files being read, to refuse cycles
    std::map<std::string, InlineFile> inline_cache_;
    std::unordered_map<NodeId, uint32_t> inline_file_;  // Inline node -> the file it read
    std::map<std::string, std::shared_ptr<ProtoScope>> proto_files_;
    size_t inline_files_ = 0;
};

void set_roots(LoadedScene& scene, const fs::path& main, const LoadOptions& options) {
    scene.main_file = main;
    if (!options.sandbox) return;
    std::error_code ec;
    const fs::path dir =
        options.sandbox_dir.empty() ? fs::absolute(main, ec).parent_path() : options.sandbox_dir;
    scene.allowed_roots.push_back(fs::weakly_canonical(fs::absolute(dir, ec), ec));
    for (const fs::path& p : options.allowed_roots) {
        fs::path c = fs::weakly_canonical(fs::absolute(p, ec), ec);
        scene.allowed_roots.push_back(c);
    }
}

}  // namespace

// The readers recurse once per nesting level; LoadLimits::max_nesting_depth bounds that, and this
// stack holds it with room to spare in any build (sanitizers make frames several times larger).
static void run_on_large_stack(const std::function<void()>& work) {
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, size_t(512) << 20);  // address space only; pages come as used
    pthread_t thread;
    auto trampoline = [](void* arg) -> void* {
        (*static_cast<const std::function<void()>*>(arg))();
        return nullptr;
    };
    if (pthread_create(&thread, &attr, trampoline, const_cast<std::function<void()>*>(&work)) !=
        0) {
        work();  // no thread to be had: read on this stack
    } else {
        pthread_join(thread, nullptr);
    }
    pthread_attr_destroy(&attr);
}

static LoadedScene load_scene_source(SourceText text, const std::string& path,
                                     const LoadOptions& options) {
    LoadedScene scene;
    set_roots(scene, path, options);
    uint32_t file = scene.sources.add(path, std::move(text));
    bool read_again = false;
    run_on_large_stack([&] {
        try {
            Loader loader(scene, options);
            loader.enter_main_file(path);
            ClassicResult r = loader.read_source(file, 0);
            scene.tree.roots = std::move(r.roots);
            scene.tree.root_length_scale = r.units.length;
            scene.consumed_pieces = std::move(r.consumed);
            // A UNIT angle after consumed pieces converts angles they would lack (none before
            // them: the reader reads such pieces itself). Rare enough to read again. Other units
            // need nothing: lengths scale the root group, mass and force no field drawn.
            read_again = r.units.angle != 1.0 && !scene.consumed_pieces.empty();
        } catch (const std::bad_alloc&) {
            scene.diagnostics.error_in_file(path, "out of memory while reading the scene");
        }
    });
    if (read_again) {
        LoadOptions whole = options;
        whole.piece_consumer = nullptr;
        return load_scene_source(scene.sources.take_text(file), path, whole);
    }
    if (!scene.consumed_pieces.empty()) scene.piece_consumer = options.piece_consumer;
    return scene;
}

LoadedScene load_scene_text(std::string text, const std::string& path, const LoadOptions& options) {
    return load_scene_source(SourceText(std::move(text)), path, options);
}

LoadedScene load_scene(const fs::path& path, const LoadOptions& options) {
    SourceText text;
    try {
        text = read_source_text(path, options.limits.max_file_bytes);
    } catch (const std::exception& e) {
        LoadedScene scene;
        scene.main_file = path;
        scene.diagnostics.error_in_file(path.string(), e.what());
        return scene;
    }
    return load_scene_source(std::move(text), path.string(), options);
}

}  // namespace vr
