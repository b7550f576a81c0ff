#pragma once
// Snapshot of a PlaneIdentifier's state (global plane table with footprints and union-find,
// the 5-window vote history, the window counter) so a saved session resumes identification with
// the same plane ids as the ids stored in its TSDF voxels. Parameters and the cue are not saved.
#include "core/io/byte_stream.h"
#include "core/planes/plane_identification.h"

namespace rrg {

struct PlaneStateIo {
  static void write(io::ByteWriter& w, const PlaneIdentifier& id);
  // Throws std::runtime_error (from the reader) on truncated or corrupt data.
  static void read(io::ByteReader& r, PlaneIdentifier& id);
};

}  // namespace rrg
