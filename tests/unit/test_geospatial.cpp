// Geospatial conversions (src/core/geo.h) against GeographicLib's own command-line tools, whose
// output is stored in tests/data/geo/ (README there names the commands).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/geo.h"

namespace vr {
namespace {

std::vector<std::vector<double>> read_rows(const std::string& name) {
    std::ifstream in(std::string(VRMLRAY_SOURCE_DIR) + "/tests/data/geo/" + name);
    EXPECT_TRUE(in) << name;
    std::vector<std::vector<double>> rows;
    for (std::string line; std::getline(in, line);) {
        std::istringstream s(line);
        std::vector<double> row;
        for (double v; s >> v;) row.push_back(v);
        if (!row.empty()) rows.push_back(row);
    }
    return rows;
}

geo::System system_of(std::vector<std::string> words) {
    std::vector<std::string> problems;
    const geo::System s = geo::parse_system(words, problems);
    EXPECT_TRUE(problems.empty()) << problems.front();
    return s;
}

// 1e-9 relative to the Earth's radius is 6 mm: the tools print 9 decimals (1 nm), and GeographicLib
// is exact to nanometres, so only our own arithmetic could miss.
void expect_close(const Vec3& got, const std::vector<double>& want, const std::string& what) {
    const double scale = 6.4e6;
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(got[i], want[i], 1e-9 * scale) << what << " component " << i;
}

TEST(Geospatial, GeodeticToGeocentricMatchesCartConvertOnWgs84AndInternational) {
    const auto points = read_rows("gd_points.txt");
    const auto wgs84 = read_rows("gd_wgs84_cartconvert.txt");
    const auto international = read_rows("gd_international_cartconvert.txt");
    ASSERT_EQ(points.size(), 6u);
    ASSERT_EQ(wgs84.size(), points.size());
    ASSERT_EQ(international.size(), points.size());
    const geo::System we = system_of({"GD", "WE"});
    const geo::System in = system_of({"GD", "IN"});
    const geo::System lon_first = system_of({"GD", "longitude_first"});
    for (size_t i = 0; i < points.size(); ++i) {
        const Vec3 p(points[i][0], points[i][1], points[i][2]);
        expect_close(geo::to_geocentric(we, p), wgs84[i], "WGS84 point " + std::to_string(i));
        expect_close(geo::to_geocentric(in, p), international[i],
                     "International point " + std::to_string(i));
        expect_close(geo::to_geocentric(lon_first, Vec3(p.y, p.x, p.z)), wgs84[i],
                     "longitude_first point " + std::to_string(i));
    }
    // The default system (no strings) is GD on WGS84.
    expect_close(geo::to_geocentric(system_of({}), Vec3(points[0][0], points[0][1], points[0][2])),
                 wgs84[0], "default system");
}

TEST(Geospatial, UtmToGeocentricMatchesGeoConvertThenCartConvert) {
    const auto want = read_rows("utm_wgs84_geoconvert_cartconvert.txt");
    ASSERT_EQ(want.size(), 3u);
    // utm_points.txt: 10n 572227 4145173 0 / 56s 334368.6 6250948.3 58.5 / 33n 500000 0 100.
    // X3D's order is northing first unless "easting_first".
    expect_close(geo::to_geocentric(system_of({"UTM", "Z10"}), Vec3(4145173, 572227, 0)), want[0],
                 "zone 10 north");
    expect_close(
        geo::to_geocentric(system_of({"UTM", "Z56", "S"}), Vec3(6250948.3, 334368.6, 58.5)),
        want[1], "zone 56 south");
    expect_close(
        geo::to_geocentric(system_of({"UTM", "Z33", "easting_first"}), Vec3(500000, 0, 100)),
        want[2], "zone 33 easting first");
}

TEST(Geospatial, GeocentricRoundTripsThroughGeodetic) {
    const geo::System gc = system_of({"GC"});
    const Vec3 p(-2504514.520968652, -4657877.377830366, 3553465.425105664);
    EXPECT_EQ(geo::to_geocentric(gc, p), p);
    const geo::Geodetic g = geo::to_geodetic(gc, p);
    EXPECT_NEAR(g.latitude, 34.07636, 1e-11);  // the point gd_points.txt's first line made
    EXPECT_NEAR(g.longitude, -118.26667, 1e-11);
    EXPECT_NEAR(g.height, 0.0, 1e-8);
}

TEST(Geospatial, GeoOriginRotateYUpPutsTheLocalUpOnY) {
    const geo::System gd = system_of({"GD"});
    const Vec3 at(34.07636, -118.26667, 0.0);
    const geo::Origin plain = geo::make_origin(gd, at, false);
    const geo::Origin up = geo::make_origin(gd, at, true);
    // 100 m straight up from the origin, along the ellipsoid normal: (0, 100, 0) once rotated.
    const Vec3 above = geo::to_geocentric(gd, Vec3(at.x, at.y, 100.0));
    const Vec3 a = up.world_point(above);
    EXPECT_NEAR(a.x, 0.0, 1e-8);
    EXPECT_NEAR(a.y, 100.0, 1e-8);
    EXPECT_NEAR(a.z, 0.0, 1e-8);
    // Without the rotation the offset is the geocentric difference, 100 m along the normal
    // (cos(lat)cos(lon), cos(lat)sin(lon), sin(lat)).
    const Vec3 b = plain.world_point(above);
    const double lat = at.x * kPi / 180, lon = at.y * kPi / 180;
    EXPECT_NEAR(b.x, 100 * std::cos(lat) * std::cos(lon), 1e-8);
    EXPECT_NEAR(b.y, 100 * std::cos(lat) * std::sin(lon), 1e-8);
    EXPECT_NEAR(b.z, 100 * std::sin(lat), 1e-8);
    // A point a little north of the origin lies towards -Z, one to the east towards +X.
    const Vec3 north = up.world_point(geo::to_geocentric(gd, Vec3(at.x + 1e-3, at.y, 0.0)));
    EXPECT_LT(north.z, -100.0);
    EXPECT_NEAR(north.x, 0.0, 1e-6);
    const Vec3 east = up.world_point(geo::to_geocentric(gd, Vec3(at.x, at.y + 1e-3, 0.0)));
    EXPECT_GT(east.x, 90.0);
    EXPECT_NEAR(east.z, 0.0, 1e-3);  // the parallel curves away from the tangent plane's x axis
}

TEST(Geospatial, SystemStringsProblemsAreReported) {
    std::vector<std::string> problems;
    const std::vector<std::string> no_zone = {"UTM"};
    geo::parse_system(no_zone, problems);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_NE(problems[0].find("zone"), std::string::npos);
    problems.clear();
    const std::vector<std::string> odd = {"GD", "XX"};
    const geo::System s = geo::parse_system(odd, problems);
    EXPECT_EQ(problems.size(), 1u);
    EXPECT_EQ(s.ellipsoid.a, 6378137.0);           // WGS84 kept
    const std::vector<std::string> gdc = {"GDC"};  // GeoVRML's spelling
    problems.clear();
    EXPECT_EQ(geo::parse_system(gdc, problems).frame, geo::Frame::Geodetic);
    EXPECT_TRUE(problems.empty());
}

}  // namespace
}  // namespace vr
