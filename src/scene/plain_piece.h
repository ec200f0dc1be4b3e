// A piece of a large classic-encoding file read straight from its tokens into a scene fragment,
// with no node tree (issue 16). Molecule exporters write one small subtree per atom or bond:
// Transform { translation .. rotation .. children Shape { appearance Appearance { material
// Material {..} } geometry Sphere {..} } }. Reading that into the node tree and building the
// fragment from the tree took more time than tokenizing it; this reader builds the same fragment
// (build_fragment() of the piece's tree, array for array and index for index) from the tokens.
//
// It takes only the plain pattern: Transform, Group, Shape, Appearance, Material, Sphere, Box,
// Cylinder and Cone nodes with numeric and boolean fields, children, appearance, material and
// geometry node fields, and USE of a name DEF'd before the piece only as a Shape's appearance (the
// splice resolves it). On anything else, or anything the tree's reading or build would warn about
// (a DEF, a string, metadata, a field given twice, a singular transform, a zero radius), it gives
// up and the piece is read into a tree as before: the messages stay the tree's.
#pragma once
#include <optional>

#include "parser/piece_consumer.h"
#include "scene/scene.h"

namespace vr {

struct PlainPiece {
    Scene fragment;
    TextConsumed counts;  // what the node tree would have counted
};

// The piece's fragment, or nullopt if the piece is not plain.
std::optional<PlainPiece> read_plain_piece(const PieceText& text);

}  // namespace vr
