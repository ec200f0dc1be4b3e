// Node tree -> typed scene for the Geospatial component (X3D 19775-1 clause 25): geoSystem and
// GeoOrigin, GeoCoordinate points, GeoLocation and GeoTransform matrices, GeoLOD's level,
// GeoViewpoint and GeoElevationGrid. Every geo coordinate becomes a world coordinate here, in
// double precision (src/core/geo.h), with the node's GeoOrigin subtracted (and its rotateYUp
// rotation).
#include <cmath>
#include <glm/gtc/quaternion.hpp>

#include "scene/build_internal.h"
#include "scene/transform.h"

namespace vr::detail {

geo::System Builder::geo_system(NodeId id) {
    std::vector<std::string> problems;
    const std::vector<std::string> words = strings(id, "geoSystem"_n);
    const geo::System s = geo::parse_system(words, problems);
    for (const std::string& p : problems) warn(id, "geo-system", p);
    return s;
}

geo::Origin Builder::geo_origin(NodeId id) {
    const NodeId o = node(id, "geoOrigin"_n);
    if (o == kNullNode) return geo::Origin{};
    if (type(o) != "GeoOrigin"_n) {
        warn(o, "wrong-type", "is not a GeoOrigin; coordinates stay geocentric");
        return geo::Origin{};
    }
    const geo::Origin origin =
        geo::make_origin(geo_system(o), vec3(o, "geoCoords"_n), boolean(o, "rotateYUp"_n));
    if (!std::isfinite(origin.geocentric.x)) {
        warn(o, "geo-coords", "geoCoords lie outside its geoSystem; coordinates stay geocentric");
        return geo::Origin{};
    }
    return origin;
}

std::vector<Vec3> Builder::geo_points(NodeId id) {
    const geo::System system = geo_system(id);
    const geo::Origin origin = geo_origin(id);
    std::vector<Vec3> points = vec3s(id, "point"_n);
    for (Vec3& p : points) p = origin.world_point(geo::to_geocentric(system, p));
    return points;
}

bool Builder::coordinate_points(NodeId c, std::vector<Vec3>& points) {
    if (type(c) == "Coordinate"_n || type(c) == "CoordinateDouble"_n) {
        points = vec3s(c, "point"_n);
        return true;
    }
    if (type(c) == "GeoCoordinate"_n) {
        points = geo_points(c);
        return true;
    }
    return false;
}

void Builder::set_group_matrix(NodeId id, sg::Group& group, const Mat4& m) {
    if (is_singular(m)) {
        group.singular = true;
        warn(id, "singular",
             all_finite(m) ? "has a singular transform (a zero scale); its children are skipped"
                           : "has a NaN or infinite transform (coordinates outside its "
                             "geoSystem?); its children are skipped");
        return;
    }
    group.transform_kind = sg::GroupTransform::Matrix;
    group.transform = static_cast<sg::Index>(scene_.matrices.size());
    scene_.matrices.push_back(m);
}

Mat4 Builder::geo_group_matrix(NodeId id) {
    const geo::System system = geo_system(id);
    const geo::Origin origin = geo_origin(id);
    if (type(id) == "GeoLocation"_n)
        return geo::location_matrix(system, vec3(id, "geoCoords"_n), origin);
    // GeoTransform (X3D 25.4.9): translation, rotation and scale act in the tangent frame at
    // geoCenter, on children whose coordinates are world coordinates: L * T R SR S SR^-1 * L^-1.
    const Mat4 local = geo::location_matrix(system, vec3(id, "geoCenter"_n), origin);
    TransformFields f;
    f.translation = vec3(id, "translation"_n);
    f.rotation = rotation(id, "rotation"_n);
    f.scale = vec3(id, "scale"_n);
    f.scale_orientation = rotation(id, "scaleOrientation"_n);
    return local * transform_matrix(f) * glm::inverse(local);
}

std::span<const NodeId> Builder::geo_lod_children(NodeId id, bool& inlined) {
    // The reader loaded child1Url..child4Url (else rootUrl) as the node's inline roots
    // (parser/load.cpp); without them, the rootNode the file holds.
    inlined = false;
    if (const auto it = tree_.inline_roots.find(id); it != tree_.inline_roots.end()) {
        inlined = true;
        return it->second;
    }
    return nodes(id, "rootNode"_n);
}

void Builder::read_geo_viewpoint(NodeId id, sg::Viewpoint& v) {
    // X3D 25.4.10: the position in the geoSystem; the orientation relative to the local frame there
    // (its default looks north along the tangent plane, +Y up).
    const geo::System system = geo_system(id);
    const geo::Origin origin = geo_origin(id);
    const Vec3 coords = vec3(id, "position"_n);
    const Vec3 geocentric = geo::to_geocentric(system, coords);
    if (!std::isfinite(geocentric.x)) {
        warn(id, "geo-coords", "position lies outside its geoSystem; the viewpoint is not used");
        v.position = Vec3(0.0);
        return;
    }
    v.position = origin.world_point(geocentric);
    const Mat3 frame =
        origin.world_from_geocentric * geo::local_frame(geo::to_geodetic(system, coords));
    const Mat3 world = frame * rotation_matrix(v.orientation);
    const glm::dquat q = glm::quat_cast(world);
    v.orientation = Vec4(glm::axis(q), glm::angle(q));
}

std::unique_ptr<sg::IndexedFaceSet> Builder::make_geo_elevation_grid(NodeId id) {
    auto faces = std::make_unique<sg::IndexedFaceSet>();
    const sg::Origin where = origin(id);
    read_vertex_data(id, faces->data, false, where);
    const geo::System system = geo_system(id);
    const geo::Origin geo_origin_ = geo_origin(id);
    const int nx = integer(id, "xDimension"_n), nz = integer(id, "zDimension"_n);
    const double dx = number(id, "xSpacing"_n), dz = number(id, "zSpacing"_n);
    const double y_scale = number(id, "yScale"_n);
    const Vec3 grid_origin = vec3(id, "geoGridOrigin"_n);
    const std::vector<double> height = numbers(id, "height"_n);
    if (system.frame == geo::Frame::Geocentric) {
        warn(id, "geo-system", "a GC grid has no x and z directions (X3D 25.4.3); not rendered");
        return faces;
    }
    if (nx < 2 || nz < 2 || height.size() < size_t(nx) * size_t(nz) || !(dx > 0.0) || !(dz > 0.0)) {
        warn(id, "dimension",
             "needs xDimension and zDimension of at least 2, positive spacings and a height a "
             "vertex; not rendered");
        return faces;
    }
    // Grid x runs along longitude (GD) or easting (UTM), z along latitude or northing (X3D
    // 25.4.3), each in the coordinate order of the geoSystem.
    const bool x_first =
        system.frame == geo::Frame::Geodetic ? system.longitude_first : system.easting_first;
    const double x0 = x_first ? grid_origin.x : grid_origin.y;
    const double z0 = x_first ? grid_origin.y : grid_origin.x;
    std::vector<Vec3>& coords = faces->data.coords;
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const double x = x0 + i * dx, z = z0 + j * dz;
            const double h = grid_origin.z + height[size_t(i) + size_t(j) * size_t(nx)] * y_scale;
            const Vec3 c = x_first ? Vec3(x, z, h) : Vec3(z, x, h);
            coords.push_back(geo_origin_.world_point(geo::to_geocentric(system, c)));
        }
    const bool want_default_uvs = faces->data.texcoords.empty();
    for (int j = 0; want_default_uvs && j < nz; ++j)
        for (int i = 0; i < nx; ++i)
            faces->data.texcoords.push_back(Vec2(double(i) / (nx - 1), double(j) / (nz - 1)));
    // Quads wound so that their front faces away from the ellipsoid for ccw TRUE, whichever way
    // the grid's axes run (x east and z north is a left-handed grid seen from above).
    // Tested on a middle cell: a whole-globe grid's edge rows collapse into the poles.
    const size_t a = size_t((nz - 1) / 2) * size_t(nx) + size_t((nx - 1) / 2);
    const Vec3 up =
        geo_origin_.world_from_geocentric *
        geo::to_geocentric(system,
                           x_first ? Vec3(x0 + dx * ((nx - 1) / 2), z0 + dz * ((nz - 1) / 2), 0.0)
                                   : Vec3(z0 + dz * ((nz - 1) / 2), x0 + dx * ((nx - 1) / 2), 0.0));
    const Vec3 across = coords[a + 1] - coords[a];
    const Vec3 along = coords[a + size_t(nx)] - coords[a];
    const bool z_then_x = glm::dot(glm::cross(along, across), up) >= 0.0;
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const int32_t a = j * nx + i, b = a + 1, c = a + nx + 1, d = a + nx;
            if (z_then_x)
                faces->coord_index.insert(faces->coord_index.end(), {a, d, c, b, -1});
            else
                faces->coord_index.insert(faces->coord_index.end(), {a, b, c, d, -1});
        }
    faces->ccw = boolean(id, "ccw"_n);
    faces->solid = boolean(id, "solid"_n);
    faces->convex = true;
    faces->color_per_vertex = boolean(id, "colorPerVertex"_n);
    faces->normal_per_vertex = boolean(id, "normalPerVertex"_n);
    faces->crease_angle = number(id, "creaseAngle"_n);
    return faces;
}

}  // namespace vr::detail
