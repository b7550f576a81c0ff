#pragma once
// Snapshot of a PlaneIdentifier's state (global plane table with footprints and union-find,
// the 5-window vote history, the window counter) so a saved session resumes identification with
// the same plane ids as the ids stored in its TSDF voxels. Parameters and the cue are not saved.
// Also the reflective fill's carried surfaces (FillRegion, reflective_fill.h).
#include "core/io/byte_stream.h"
#include "core/planes/plane_identification.h"
#include "core/planes/reflective_fill.h"

#include <span>
#include <vector>

namespace rrg {

struct PlaneStateIo {
  static void write(io::ByteWriter& w, const PlaneIdentifier& id);
  // Throws std::runtime_error (from the reader) on truncated or corrupt data.
  static void read(io::ByteReader& r, PlaneIdentifier& id);
  // The global plane table alone, as write / read store it (read_table: in that format `version`).
  static void write_table(io::ByteWriter& w, const GlobalPlaneTable& t);
  static void read_table(io::ByteReader& r, GlobalPlaneTable& t, uint32_t version);

  static void write_fill_regions(io::ByteWriter& w, std::span<const FillRegion> regions);
  static std::vector<FillRegion> read_fill_regions(io::ByteReader& r);  // throws as read()

 private:
  static void put_footprint(io::ByteWriter& w, const Footprint& f);
  static Footprint get_footprint(io::ByteReader& r);
};

}  // namespace rrg
