// The scene fragment of a plain piece (src/scene/plain_piece.h) as bytes, for processes that read a
// large file's pieces between them and send each other what they built (app/shared_pieces.h,
// docs/mpi.md "Split reading"). What a plain piece holds is all it carries: groups, child
// references, translations, matrices, shapes, the four primitive geometries, appearances without
// textures and Phong materials, and the counts the node tree would have made. Interned names
// (node types, the names a piece USEs from before it) are numbers private to a process, so they
// travel as text.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "parser/piece_consumer.h"
#include "scene/scene.h"

namespace vr {

// One piece as it travels: its index, and its fragment with the counts, or nothing when the piece
// is not plain (every process then reads it itself).
struct WirePiece {
    uint32_t piece = 0;
    std::optional<Scene> fragment;
    TextConsumed counts;
};

// Whether `fragment` holds only what the wire carries (a plain piece's always does).
bool fits_wire(const Scene& fragment);

// The pieces as one message: a table of names, then piece after piece. Fragments that do not
// fits_wire go as "not plain".
std::vector<uint8_t> pack_pieces(std::span<const WirePiece> pieces);
// The pieces of a message pack_pieces made, in its order; throws std::runtime_error on a message
// that ends early.
std::vector<WirePiece> unpack_pieces(std::span<const uint8_t> message);

}  // namespace vr
