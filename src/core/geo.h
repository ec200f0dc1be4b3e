// Geospatial coordinates (X3D 19775-1 clause 25): the spatial reference frames a `geoSystem` names
// (geodetic "GD", geocentric "GC", Universal Transverse Mercator "UTM", on one of the 23 ellipsoids
// of X3D table 25.3), converted to geocentric coordinates by GeographicLib, the local east-up-south
// frame at a point, and a GeoOrigin's offset and `rotateYUp` rotation. Double precision throughout:
// geocentric coordinates are about 6.4e6 m, and the scene build subtracts the GeoOrigin before
// anything is rounded.
//
// Coordinates are given in the frame's own order (X3D 25.2.3): GD latitude, longitude (degrees),
// height (metres above the ellipsoid), or longitude first with "longitude_first"; UTM northing,
// easting, height, or easting first with "easting_first"; GC x, y, z in metres.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "core/math.h"

namespace vr::geo {

enum class Frame : uint8_t { Geodetic, Geocentric, Utm };

struct Ellipsoid {
    double a = 0.0;  // equatorial radius, metres
    double f = 0.0;  // flattening
};
// The ellipsoid of an X3D code ("WE" WGS84, "RF" GRS80, "IN" International 1924, ...); false for
// an unknown code.
bool ellipsoid_of(const std::string& code, Ellipsoid& out);

struct System {
    Frame frame = Frame::Geodetic;
    Ellipsoid ellipsoid;           // parse_system sets it (WGS84 unless the strings name another)
    int zone = 0;                  // UTM: 1..60
    bool south = false;            // UTM: "S", the southern hemisphere (false northing 1e7 m)
    bool easting_first = false;    // UTM
    bool longitude_first = false;  // GD
};

// A geoSystem value (X3D 25.2.3). Empty strings mean the default ["GD" "WE"]. Words it cannot use
// (an unknown ellipsoid, a UTM system without a zone, the "WGS84" geoid height option that would
// need geoid data) are described in `problems`, one sentence each; the rest of the system is still
// used.
System parse_system(std::span<const std::string> words, std::vector<std::string>& problems);

struct Geodetic {
    double latitude = 0.0, longitude = 0.0;  // degrees
    double height = 0.0;                     // metres above the ellipsoid
};
// The point's geodetic coordinates on the system's ellipsoid (GC points: GeographicLib's exact
// inverse). Not finite for coordinates outside the frame (|latitude| > 90, a UTM zone of 0, ...).
Geodetic to_geodetic(const System& system, const Vec3& coords);
// The point in geocentric (earth-centred, earth-fixed) metres.
Vec3 to_geocentric(const System& system, const Vec3& coords);
// The local frame at a point (X3D 25.4.5 GeoLocation): columns +X east, +Y up (the ellipsoid
// normal), +Z south (so that -Z points north), in geocentric axes.
Mat3 local_frame(const Geodetic& at);

// A GeoOrigin (X3D 25.4.6), or none: world coordinates are geocentric coordinates minus the
// origin's, turned by the inverse of the origin's local frame when `rotate_y_up` (so that up at
// the origin is +Y).
struct Origin {
    Vec3 geocentric{0.0};
    bool rotate_y_up = false;
    Mat3 world_from_geocentric{1.0};  // identity, or the transpose of the origin's local frame

    Vec3 world_point(const Vec3& geocentric_point) const {
        return world_from_geocentric * (geocentric_point - geocentric);
    }
};
Origin make_origin(const System& system, const Vec3& coords, bool rotate_y_up);

// The transform of a GeoLocation at `coords`: its children's local frame placed at the point, in
// world coordinates (origin applied): [world_from_geocentric * frame | world_point(point)].
Mat4 location_matrix(const System& system, const Vec3& coords, const Origin& origin);

}  // namespace vr::geo
