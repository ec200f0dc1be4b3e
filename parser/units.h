// X3D UNIT statements (19775-1 3.3, 7.2.5.5; 4.3.6): a file may give its lengths, angles, masses
// and forces in units of its own. vrmlray converts every file to the initial base units (metre,
// radian, kilogram, newton), so that each file's UNITs apply to it alone and an Inline's content is
// aligned to the file that includes it.
//
// Lengths are converted by a scale, not value by value: every length of a file lives in that file's
// coordinate system (positions, sizes, radii, Fog distances, interpolated translations), so one
// uniform scale at the file's root (NodeTree::root_length_scale, NodeTree::inline_length_scale,
// applied by the scene build) converts them all, ROUTEd values included. Angles are not lengths of
// any coordinate system: they are converted in the node tree, value by value, right after the file
// is read (convert_angles). Mass and force are recorded; no node vrmlray draws has such a field.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

#include "parser/node_tree.h"
#include "parser/source.h"

namespace vr {

struct FileUnits {
    double length = 1.0;  // metres per length unit of the file
    double angle = 1.0;   // radians per angle unit
    double mass = 1.0;    // kilograms per mass unit
    double force = 1.0;   // newtons per force unit
    SourceLoc first;      // the file's first UNIT statement; invalid: none
    uint8_t seen = 0;     // categories given, a bit each in the order above
    bool any() const { return first.valid(); }
};

// Takes `UNIT category name conversionFactor` (the classic statement, or XML's <unit> in <head>).
// Returns an empty string, or why the statement is ignored (unknown category, a factor that is not
// a positive finite number, a second UNIT of a category).
std::string add_unit(FileUnits& units, std::string_view category, std::string_view factor,
                     SourceLoc where);

// Whether a UNIT statement is allowed in a file with this header version: X3D 3.3 and later.
// `version` is "3.3", "4.0", ... (empty: VRML97 or unknown).
bool units_allowed(std::string_view version);

// Multiplies by `factor` the angles among the values that file `file` itself wrote into nodes
// [first_node, tree.nodes.size()): the angle of every SFRotation/MFRotation, and the SFFloat/
// MFFloat fields the grammar gives an angle range (in pi: fieldOfView, beamWidth, skyAngle, ...)
// or that are angles without one (creaseAngle, TextureTransform.rotation). Defaults are left as
// the specification gives them, in radians.
void convert_angles(NodeTree& tree, uint32_t file, size_t first_node, double factor);

// Whether `field` of a node of type `type` (read with `decl`) holds angles, by the rule above.
bool is_angle_field(const NodeTypeDecl* decl, Name type, Name field, FieldType field_type);

}  // namespace vr
