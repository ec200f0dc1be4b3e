// The fast twin of tools/gen_molecule.py's default (PyMOL) layout, for the sizes where Python is
// the bottleneck: the Python writer spends about 35 us an atom, so the 100M-atom file of
// `bench/scale.sh --huge` (29 GB) took an hour to write; this one writes at the disk's pace.
//
// It writes the same text per atom and per bond, the same header lines, the same self-avoiding walk
// (1.5 A steps in a ball of radius 1.6 N^(1/3) + 5, up to 50 tries a step) and the same H/C/N/O/S
// mix, so a reader sees the same file structure and the same sizes within a few bytes. Its random
// numbers are its own (splitmix64, directions drawn uniformly on the sphere), so a given seed gives
// a different molecule than the Python script's; the same seed always gives the same file. VMD's
// layout (--vmd) stays Python-only: no benchmark needs it at scale.
//
// Build: g++ -O2 -std=c++20 tools/gen_molecule.cpp -o gen_molecule (bench/scale.sh does this), or
// the `gen_molecule` CMake target.
// Usage: gen_molecule N_ATOMS OUT.wrl [--seed S] [--no-bonds]
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace {

struct Element {
    double fraction;
    // The per-atom text after the translation, which depends only on the element: precomputed once.
    std::string tail;
};

struct ElementSpec {
    double fraction, radius, r, g, b;
};

// Name order, fractions, radii (A) and CPK colours as in tools/gen_molecule.py's ELEMENTS.
constexpr ElementSpec kElementSpecs[] = {
    {0.20, 0.30, 0.95, 0.95, 0.95},  // H
    {0.45, 0.60, 0.50, 0.50, 0.50},  // C
    {0.14, 0.58, 0.20, 0.30, 1.00},  // N
    {0.18, 0.55, 1.00, 0.15, 0.10},  // O
    {0.03, 0.90, 1.00, 0.85, 0.15},  // S
};

std::vector<Element> make_elements() {
    std::vector<Element> out;
    for (const ElementSpec& e : kElementSpecs) {
        char buf[512];
        std::snprintf(
            buf, sizeof buf,
            "\n children [\n  Shape {\n   appearance Appearance {\n    material Material {\n"
            "     diffuseColor %.3f %.3f %.3f\n     specularColor 0.3 0.3 0.3\n     shininess 0.2\n"
            "     ambientIntensity 0.2\n    }\n   }\n   geometry Sphere { radius %.2f }\n"
            "  }\n ]\n}\n",
            e.r, e.g, e.b, e.radius);
        out.push_back({e.fraction, buf});
    }
    return out;
}

// splitmix64: tiny, fast and well mixed; the walk needs a few draws an atom, not cryptography.
struct Rng {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

struct Vec3 {
    double x, y, z;
};

// A direction uniform on the unit sphere (Marsaglia 1972): the same distribution as the Python
// script's normalised Gaussian triple, with fewer and cheaper draws.
Vec3 unit_direction(Rng& rng) {
    for (;;) {
        const double u = 2 * rng.uniform() - 1, v = 2 * rng.uniform() - 1, s = u * u + v * v;
        if (s >= 1 || s == 0) continue;
        const double f = 2 * std::sqrt(1 - s);
        return {u * f, v * f, 1 - 2 * s};
    }
}

// The chain, one atom a call; walking it again from the same seed repeats it, so the bonds are
// written without holding 10^8 positions.
class Walk {
  public:
    Walk(uint64_t seed, double ball, const std::vector<Element>& elements)
        : rng_{seed * 0x2545f4914f6cdd1dULL + 1}, ball_(ball), elements_(elements) {}

    // Moves to the next atom; returns its element's index.
    size_t step() {
        Vec3 q{};
        // As in the Python script: after 50 tries outside the ball, the 50th is kept.
        for (int attempt = 0; attempt < 50; ++attempt) {
            const Vec3 d = unit_direction(rng_);
            q = {p_.x + 1.5 * d.x, p_.y + 1.5 * d.y, p_.z + 1.5 * d.z};
            if (std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z) < ball_) break;
        }
        p_ = q;
        double r = rng_.uniform();
        size_t e = 0;
        for (; e + 1 < elements_.size(); ++e) {
            r -= elements_[e].fraction;
            if (r <= 0) break;
        }
        return e;
    }
    const Vec3& position() const { return p_; }

  private:
    Rng rng_;
    double ball_;
    const std::vector<Element>& elements_;
    Vec3 p_{0, 0, 0};
};

// The output with its own buffer: fprintf's parsing would take most of the time an atom.
class Writer {
  public:
    explicit Writer(std::FILE* f) : f_(f) { buf_.reserve(kFlush + 4096); }
    ~Writer() { flush(); }
    void text(std::string_view s) {
        buf_.append(s);
        if (buf_.size() >= kFlush) flush();
    }
    // `v` as printf's "%.<decimals>f" writes it: std::to_chars rounds the exact binary value the
    // same way (negative zero keeps its sign), without parsing a format an atom.
    void fixed(double v, int decimals) {
        char tmp[64];
        const auto r = std::to_chars(tmp, tmp + sizeof tmp, v, std::chars_format::fixed, decimals);
        text({tmp, static_cast<size_t>(r.ptr - tmp)});
    }
    void flush() {
        if (!buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size())
            failed_ = true;
        buf_.clear();
    }
    bool failed() const { return failed_; }

  private:
    static constexpr size_t kFlush = 1 << 22;
    std::FILE* f_;
    std::string buf_;
    bool failed_ = false;
};

void write_atoms(Writer& out, long long n, uint64_t seed, double ball,
                 const std::vector<Element>& elements) {
    Walk walk(seed, ball, elements);
    for (long long i = 0; i < n; ++i) {
        const size_t e = walk.step();
        const Vec3& p = walk.position();
        out.text("Transform {\n translation ");
        out.fixed(p.x, 4);
        out.text(" ");
        out.fixed(p.y, 4);
        out.text(" ");
        out.fixed(p.z, 4);
        out.text(elements[e].tail);
    }
}

// One bond: a Cylinder along +y, turned onto a -> b, at the midpoint (the Python script's
// arithmetic).
void write_bond(Writer& out, const Vec3& a, const Vec3& b) {
    const Vec3 d{b.x - a.x, b.y - a.y, b.z - a.z};
    const double length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    Vec3 axis{d.z, 0.0, -d.x};  // y x d
    const double al = std::sqrt(axis.x * axis.x + axis.z * axis.z);
    double angle = std::acos(std::fmax(-1.0, std::fmin(1.0, d.y / length)));
    if (al < 1e-9) {
        axis = {1.0, 0.0, 0.0};
        angle = d.y > 0 ? 0.0 : M_PI;
    } else {
        axis = {axis.x / al, 0.0, axis.z / al};
    }
    out.text("Transform { translation ");
    out.fixed((a.x + b.x) / 2, 4);
    out.text(" ");
    out.fixed((a.y + b.y) / 2, 4);
    out.text(" ");
    out.fixed((a.z + b.z) / 2, 4);
    out.text(" rotation ");
    for (double v : {axis.x, axis.y, axis.z}) {
        out.fixed(v, 5);
        out.text(" ");
    }
    out.fixed(angle, 5);
    out.text(
        " children Shape { appearance Appearance { material Material { diffuseColor 0.65 0.65 0.65 "
        "} }"
        " geometry Cylinder { radius 0.15 height ");
    out.fixed(length, 4);
    out.text(" top FALSE bottom FALSE } } }\n");
}

void write_bonds(Writer& out, long long n, uint64_t seed, double ball,
                 const std::vector<Element>& elements) {
    Walk walk(seed, ball, elements);
    Vec3 prev{};
    for (long long i = 0; i < n; ++i) {
        walk.step();
        if (i > 0) write_bond(out, prev, walk.position());
        prev = walk.position();
    }
}

int usage() {
    std::fputs(
        "usage: gen_molecule N_ATOMS OUT.wrl [--seed S] [--no-bonds]\n"
        "  (VMD's layout: tools/gen_molecule.py --vmd)\n",
        stderr);
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) return usage();
    const long long n = std::atoll(argv[1]);
    const char* path = argv[2];
    uint64_t seed = 1;
    bool bonds = true;
    for (int i = 3; i < argc; ++i) {
        if (std::strcmp(argv[i], "--no-bonds") == 0) {
            bonds = false;
        } else if (std::strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            seed = std::strtoull(argv[++i], nullptr, 10);
        } else {
            return usage();
        }
    }
    if (n < 1) return usage();
    std::FILE* f = std::fopen(path, "wb");
    if (f == nullptr) {
        std::fprintf(stderr, "gen_molecule: cannot write %s: %s\n", path, std::strerror(errno));
        return 1;
    }
    const double ball = 1.6 * std::cbrt(static_cast<double>(n)) + 5;
    const std::vector<Element> elements = make_elements();
    bool failed = false;
    {
        Writer out(f);
        char head[512];
        std::snprintf(
            head, sizeof head,
            "#VRML V2.0 utf8\n# Synthetic %lld-atom molecule in PyMOL's VRML97 export style"
            " (tools/gen_molecule.cpp, seed %llu)\nViewpoint { position 0 0 %.3f fieldOfView "
            "0.785398"
            " description \"front\" }\nNavigationInfo { headlight FALSE }\nDirectionalLight { "
            "direction"
            " 0.6 -0.7 -0.4 intensity 1 ambientIntensity 0.2 }\nBackground { skyColor [ 0.1 0.1 "
            "0.15 ] }\n",
            n, static_cast<unsigned long long>(seed), ball * 3.2);
        out.text(head);
        write_atoms(out, n, seed, ball, elements);
        if (bonds) write_bonds(out, n, seed, ball, elements);
        out.flush();
        failed = out.failed();
    }
    if (std::fclose(f) != 0 || failed) {
        std::fprintf(stderr, "gen_molecule: writing %s failed: %s\n", path, std::strerror(errno));
        return 1;
    }
    return 0;
}
