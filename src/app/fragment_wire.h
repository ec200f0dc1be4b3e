// The scene fragment of a plain piece (src/scene/plain_piece.h) as it travels between processes
// that read a large file's pieces between them (app/shared_pieces.h, docs/mpi.md "Split
// reading"). A piece goes as a fixed header, then its parts, each a message of its own: the
// sender's new names, the piece's outer USE names, then each of the fragment's arrays straight
// from the sender's storage into the receiver's, with no packing and no copy out of a message.
// The geometries alone go as records (their variant holds pointers for other kinds of node).
//
// Interned names (node types, the names a piece USEs from before it) are numbers private to a
// process: each sender sends the texts of the names it interned since its last piece, and each
// receiver keeps a map from the sender's numbers to its own. Where the map is the identity (the
// processes interned the same names in the same order, as they do for a file of plain pieces
// without USE) the arrays are taken as they arrived; else every origin is renumbered.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "parser/piece_consumer.h"
#include "scene/scene.h"

namespace vr {

// Whether `fragment` holds only what the wire carries (a plain piece's always does).
bool fits_wire(const Scene& fragment);

// The fixed part of a piece on the wire. `counts` has an element count for each part, and the
// parts of no elements are not sent.
struct WireHeader {
    static constexpr size_t kMaxParts = 16;
    uint32_t piece = 0;
    uint32_t plain = 0;  // 0: not plain, no parts follow (every process reads the piece itself)
    uint32_t roots = 0, nodes = 0, uses = 0;  // TextConsumed's
    uint32_t first_name = 0;                  // the sender's number of the names part's first name
    uint32_t new_names = 0;                   // names in the names part
    uint32_t unused = 0;                      // no padding: every byte sent is set
    uint64_t counts[kMaxParts] = {};
};
static_assert(sizeof(WireHeader) == 8 * 4 + WireHeader::kMaxParts * 8);

// The texts of the names interned in this process since the last call (a sender's, for the
// names part of its next piece).
class NameTexts {
  public:
    // Bytes: for each name its length (uint32) and its text. `first`: its first name's number.
    std::vector<uint8_t> next(uint32_t& first, uint32_t& count);

  private:
    uint32_t sent_ = 0;
};

// A receiver's map from one sender's name numbers to its own.
class NameMap {
  public:
    // The sender's names [first, first + count) as NameTexts::next wrote them; throws
    // std::runtime_error if `first` is not where the last part ended, or the bytes end early.
    void add(std::span<const uint8_t> texts, uint32_t first, uint32_t count);
    bool identity() const { return identity_; }
    // Throws std::runtime_error for a number the sender never sent.
    Name operator()(uint32_t sender_name) const;

  private:
    std::vector<Name> names_;
    bool identity_ = true;
};

// A piece on the sender's side: what must live until its messages are sent.
class OutgoingPiece {
  public:
    // `fragment` null or not fits_wire: the piece goes as not plain.
    OutgoingPiece(uint32_t piece, const Scene* fragment, const TextConsumed& counts,
                  NameTexts& names);
    const WireHeader& header() const { return header_; }
    // The parts to send after the header, in order, those of no bytes left out.
    const std::vector<std::span<const uint8_t>>& parts() const { return parts_; }
    size_t bytes() const;

  private:
    WireHeader header_;
    std::vector<uint8_t> names_;
    std::vector<uint32_t> outer_;
    std::vector<std::vector<uint8_t>> copies_;  // arrays kept in more than one chunk, as one
    std::vector<uint8_t> geometries_;
    std::vector<std::span<const uint8_t>> parts_;
};

// A piece on the receiver's side: storage sized from the header, its parts received straight into
// the fragment's arrays.
class IncomingPiece {
  public:
    // Allocates the parts (std::bad_alloc when there is no room).
    explicit IncomingPiece(const WireHeader& header);
    uint32_t piece() const { return header_.piece; }
    bool plain() const { return header_.plain != 0; }
    // Where to receive the parts, in the order OutgoingPiece::parts() sends them.
    const std::vector<std::span<uint8_t>>& parts() const { return parts_; }
    // The received fragment (nullopt if not plain) and its counts, names first added to `names`
    // and then mapped through it; throws std::runtime_error on parts that do not fit together.
    std::optional<Scene> finish(NameMap& names, TextConsumed& counts) &&;

  private:
    WireHeader header_;
    std::vector<uint8_t> names_;
    std::vector<uint32_t> outer_;
    std::vector<uint8_t> geometries_;
    Scene fragment_;
    std::vector<std::span<uint8_t>> parts_;
};

}  // namespace vr
