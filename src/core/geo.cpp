#include "core/geo.h"

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/TransverseMercator.hpp>
#include <cmath>
#include <cstdlib>

namespace vr::geo {

namespace {

// X3D 19775-1 table 25.3 (the ellipsoids of the DMA/NIMA datum tables): code, a, 1/f.
struct EllipsoidRow {
    const char* code;
    double a, inverse_f;
};
constexpr EllipsoidRow kEllipsoids[] = {
    {"AA", 6377563.396, 299.3249646},  // Airy 1830
    {"AM", 6377340.189, 299.3249646},  // Modified Airy
    {"AN", 6378160.0, 298.25},         // Australian National
    {"BN", 6377483.865, 299.1528128},  // Bessel 1841 (Namibia)
    {"BR", 6377397.155, 299.1528128},  // Bessel 1841 (Ethiopia, Indonesia, ...)
    {"CC", 6378206.4, 294.9786982},    // Clarke 1866
    {"CD", 6378249.145, 293.465},      // Clarke 1880
    {"EA", 6377276.345, 300.8017},     // Everest (India 1830)
    {"EB", 6377298.556, 300.8017},     // Everest (Sabah and Sarawak)
    {"EC", 6377301.243, 300.8017},     // Everest (India 1956)
    {"ED", 6377295.664, 300.8017},     // Everest (W. Malaysia 1969)
    {"EE", 6377304.063, 300.8017},     // Everest (W. Malaysia and Singapore 1948)
    {"EF", 6377309.613, 300.8017},     // Everest (Pakistan)
    {"FA", 6378155.0, 298.3},          // Modified Fischer 1960
    {"HE", 6378200.0, 298.3},          // Helmert 1906
    {"HO", 6378270.0, 297.0},          // Hough 1960
    {"ID", 6378160.0, 298.247},        // Indonesian 1974
    {"IN", 6378388.0, 297.0},          // International 1924
    {"KA", 6378245.0, 298.3},          // Krassovsky 1940
    {"RF", 6378137.0, 298.257222101},  // Geodetic Reference System 1980
    {"SA", 6378160.0, 298.25},         // South American 1969
    {"WD", 6378135.0, 298.26},         // WGS 72
    {"WE", 6378137.0, 298.257223563},  // WGS 84
};

constexpr double kUtmScale = 0.9996;  // UTM's central scale factor
constexpr double kUtmFalseEasting = 500000.0;
constexpr double kUtmFalseNorthingSouth = 10000000.0;

// GeographicLib's objects precompute their series per ellipsoid (TransverseMercator's cost
// microseconds): one of each kept per thread for the last ellipsoid, since a grid's posts share
// one.
const GeographicLib::Geocentric& geocentric_for(const Ellipsoid& e) {
    thread_local Ellipsoid last{-1.0, -1.0};
    thread_local GeographicLib::Geocentric earth = GeographicLib::Geocentric::WGS84();
    if (last.a != e.a || last.f != e.f) earth = GeographicLib::Geocentric(e.a, e.f), last = e;
    return earth;
}
const GeographicLib::TransverseMercator& utm_for(const Ellipsoid& e) {
    thread_local Ellipsoid last{-1.0, -1.0};
    thread_local GeographicLib::TransverseMercator tm = GeographicLib::TransverseMercator::UTM();
    if (last.a != e.a || last.f != e.f)
        tm = GeographicLib::TransverseMercator(e.a, e.f, kUtmScale), last = e;
    return tm;
}

Ellipsoid wgs84() { return Ellipsoid{6378137.0, 1.0 / 298.257223563}; }

// "Z10" (or "z10"): the UTM zone number, 0 when the word is no zone.
int zone_of(const std::string& word) {
    if (word.size() < 2 || (word[0] != 'Z' && word[0] != 'z')) return 0;
    char* end = nullptr;
    const long zone = std::strtol(word.c_str() + 1, &end, 10);
    return *end == '\0' && zone >= 1 && zone <= 60 ? int(zone) : 0;
}

}  // namespace

bool ellipsoid_of(const std::string& code, Ellipsoid& out) {
    for (const EllipsoidRow& row : kEllipsoids)
        if (code == row.code) {
            out = Ellipsoid{row.a, 1.0 / row.inverse_f};
            return true;
        }
    return false;
}

System parse_system(std::span<const std::string> words, std::vector<std::string>& problems) {
    System s;
    s.ellipsoid = wgs84();
    if (words.empty()) return s;
    const std::string& kind = words[0];
    // "GDC" and "GCC" are GeoVRML's and X3D 3.0's spellings, still accepted by X3D 25.2.3.
    if (kind == "GD" || kind == "GDC")
        s.frame = Frame::Geodetic;
    else if (kind == "GC" || kind == "GCC")
        s.frame = Frame::Geocentric;
    else if (kind == "UTM")
        s.frame = Frame::Utm;
    else
        problems.push_back("geoSystem \"" + kind + "\" is not GD, GC or UTM; GD is used");
    for (size_t i = 1; i < words.size(); ++i) {
        const std::string& w = words[i];
        Ellipsoid e;
        if (s.frame != Frame::Geocentric && ellipsoid_of(w, e)) {
            s.ellipsoid = e;
        } else if (s.frame == Frame::Utm && zone_of(w) > 0) {
            s.zone = zone_of(w);
        } else if (s.frame == Frame::Utm && (w == "S" || w == "s")) {
            s.south = true;
        } else if (s.frame == Frame::Utm && w == "easting_first") {
            s.easting_first = true;
        } else if (s.frame == Frame::Utm && w == "northing_first") {
            s.easting_first = false;
        } else if (s.frame == Frame::Geodetic && w == "longitude_first") {
            s.longitude_first = true;
        } else if (s.frame == Frame::Geodetic && w == "latitude_first") {
            s.longitude_first = false;
        } else if (w == "WGS84" && s.frame != Frame::Geocentric) {
            problems.push_back(
                "geoSystem \"WGS84\" (heights above the geoid) needs geoid data vrmlray does not "
                "have; heights are taken above the ellipsoid");
        } else {
            problems.push_back("geoSystem word \"" + w + "\" is not understood; ignored");
        }
    }
    if (s.frame == Frame::Utm && s.zone == 0)
        problems.push_back("a UTM geoSystem needs a zone (\"Z1\" to \"Z60\"); nothing is placed");
    return s;
}

Geodetic to_geodetic(const System& s, const Vec3& c) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Geodetic g;
    switch (s.frame) {
        case Frame::Geodetic:
            g.latitude = s.longitude_first ? c.y : c.x;
            g.longitude = s.longitude_first ? c.x : c.y;
            g.height = c.z;
            if (!(std::abs(g.latitude) <= 90.0) || !std::isfinite(g.longitude)) g.latitude = nan;
            return g;
        case Frame::Geocentric: {
            geocentric_for(s.ellipsoid).Reverse(c.x, c.y, c.z, g.latitude, g.longitude, g.height);
            return g;
        }
        case Frame::Utm: {
            if (s.zone == 0) return Geodetic{nan, nan, nan};
            const double northing = s.easting_first ? c.y : c.x;
            const double easting = s.easting_first ? c.x : c.y;
            const GeographicLib::TransverseMercator& tm = utm_for(s.ellipsoid);
            const double central_meridian = 6.0 * s.zone - 183.0;
            tm.Reverse(central_meridian, easting - kUtmFalseEasting,
                       northing - (s.south ? kUtmFalseNorthingSouth : 0.0), g.latitude,
                       g.longitude);
            g.height = c.z;
            return g;
        }
    }
    return g;
}

Vec3 to_geocentric(const System& s, const Vec3& c) {
    if (s.frame == Frame::Geocentric) return c;
    const Geodetic g = to_geodetic(s, c);
    if (!std::isfinite(g.latitude) || !std::isfinite(g.longitude) || !std::isfinite(g.height))
        return Vec3(std::numeric_limits<double>::quiet_NaN());
    Vec3 out;
    geocentric_for(s.ellipsoid).Forward(g.latitude, g.longitude, g.height, out.x, out.y, out.z);
    return out;
}

Mat3 local_frame(const Geodetic& at) {
    const double lat = at.latitude * kPi / 180.0, lon = at.longitude * kPi / 180.0;
    const Vec3 east(-std::sin(lon), std::cos(lon), 0.0);
    const Vec3 up(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
    const Vec3 north(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat));
    return Mat3(east, up, -north);
}

Origin make_origin(const System& system, const Vec3& coords, bool rotate_y_up) {
    Origin o;
    o.geocentric = to_geocentric(system, coords);
    o.rotate_y_up = rotate_y_up;
    if (rotate_y_up)
        o.world_from_geocentric = glm::transpose(local_frame(to_geodetic(system, coords)));
    return o;
}

Mat4 location_matrix(const System& system, const Vec3& coords, const Origin& origin) {
    const Mat3 rotation = origin.world_from_geocentric * local_frame(to_geodetic(system, coords));
    Mat4 m(rotation);
    m[3] = Vec4(origin.world_point(to_geocentric(system, coords)), 1.0);
    return m;
}

}  // namespace vr::geo
