#include "core/planes/plane_state_io.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace rrg {
namespace {

void put_v3(io::ByteWriter& w, const Eigen::Vector3f& v) { w.put(v.x()), w.put(v.y()), w.put(v.z()); }
Eigen::Vector3f get_v3(io::ByteReader& r) {
  const float x = r.get<float>(), y = r.get<float>(), z = r.get<float>();
  return {x, y, z};
}
void put_box(io::ByteWriter& w, const Box2& b) {
  w.put(b.min.x()), w.put(b.min.y()), w.put(b.max.x()), w.put(b.max.y()), w.put<uint8_t>(b.empty);
}
Box2 get_box(io::ByteReader& r) {
  Box2 b;
  b.min.x() = r.get<float>(), b.min.y() = r.get<float>(), b.max.x() = r.get<float>(), b.max.y() = r.get<float>();
  b.empty = r.get<uint8_t>() != 0;
  return b;
}

}  // namespace

void PlaneStateIo::put_footprint(io::ByteWriter& w, const Footprint& f) {
  put_v3(w, f.basis_.origin), put_v3(w, f.basis_.u), put_v3(w, f.basis_.v);
  w.put(f.cell_);
  put_box(w, f.box_);
  std::vector<uint64_t> cells(f.cells_.begin(), f.cells_.end());
  std::sort(cells.begin(), cells.end());  // the same bytes for the same footprint
  w.put_vector(cells);
}

Footprint PlaneStateIo::get_footprint(io::ByteReader& r) {
  Footprint f;
  f.basis_.origin = get_v3(r), f.basis_.u = get_v3(r), f.basis_.v = get_v3(r);
  f.cell_ = r.get<float>();
  if (!(f.cell_ > 0.0f)) throw std::runtime_error(r.what() + ": footprint cell size is not > 0");
  f.box_ = get_box(r);
  for (uint64_t c : r.get_vector<uint64_t>()) f.cells_.insert(c);
  return f;
}

void PlaneStateIo::write_fill_regions(io::ByteWriter& w, std::span<const FillRegion> regions) {
  w.put<uint64_t>(regions.size());
  for (const FillRegion& g : regions) {
    w.put_string(g.label);
    put_v3(w, g.plane.n);
    w.put(g.plane.d);
    put_footprint(w, g.footprint);
  }
}

std::vector<FillRegion> PlaneStateIo::read_fill_regions(io::ByteReader& r) {
  const auto n = r.get<uint64_t>();
  if (n > r.remaining()) throw std::runtime_error(r.what() + ": corrupt fill region count");
  std::vector<FillRegion> regions(n);
  for (FillRegion& g : regions) {
    g.label = r.get_string();
    g.plane.n = get_v3(r);
    g.plane.d = r.get<float>();
    if (!(std::abs(g.plane.n.norm() - 1.0f) < 1e-3f)) throw std::runtime_error(r.what() + ": fill region normal is not unit");
    g.footprint = get_footprint(r);
  }
  return regions;
}

void PlaneStateIo::write_table(io::ByteWriter& w, const GlobalPlaneTable& t) {
  w.put<uint64_t>(t.planes_.size());
  for (const GlobalPlane& g : t.planes_) {
    w.put<int32_t>(g.id);
    put_v3(w, g.plane.n);
    w.put(g.plane.d);
    put_v3(w, g.centroid);
    w.put<int64_t>(g.moments.count_);
    for (double s : g.moments.s_) w.put(s);
    put_footprint(w, g.footprint);
    w.put<int64_t>(g.first_seen), w.put<int64_t>(g.last_seen);
    w.put<int32_t>(g.observations);
    w.put<uint8_t>(g.alive);
    w.put_vector(std::vector<int32_t>(g.apart.begin(), g.apart.end()));
    w.put<float>(g.same_plane_distance);
    w.put<uint64_t>(g.bridged.size());
    for (const auto& [other, frame] : g.bridged) w.put<int32_t>(other), w.put<int64_t>(frame);
  }
  std::vector<int32_t> parent(t.parent_.begin(), t.parent_.end());
  w.put_vector(parent);
}

void PlaneStateIo::write(io::ByteWriter& w, const PlaneIdentifier& id) {
  w.put<uint32_t>(3);  // format version (2: GlobalPlane::apart; 3: same_plane_distance, bridged)
  w.put<int64_t>(id.window_);
  write_table(w, id.table_);
  const ReflectiveVote& v = id.vote_;
  w.put<uint64_t>(v.history_.size());
  for (const auto& [plane, hist] : v.history_) {
    w.put<int32_t>(plane);
    w.put<uint64_t>(hist.size());
    for (const auto& [window, outcome] : hist) w.put<int64_t>(window), w.put<uint8_t>(outcome);
  }
  std::vector<int32_t> lookup(v.lookup_.begin(), v.lookup_.end());
  w.put_vector(lookup);
}

void PlaneStateIo::read_table(io::ByteReader& r, GlobalPlaneTable& t, uint32_t version) {
  const auto n = r.get<uint64_t>();
  if (n > r.remaining()) throw std::runtime_error(r.what() + ": corrupt plane count");
  t.planes_.clear();
  for (uint64_t i = 0; i < n; ++i) {
    GlobalPlane g;
    g.id = r.get<int32_t>();
    g.plane.n = get_v3(r);
    g.plane.d = r.get<float>();
    g.centroid = get_v3(r);
    g.moments.count_ = r.get<int64_t>();
    for (double& s : g.moments.s_) s = r.get<double>();
    g.footprint = get_footprint(r);
    g.first_seen = r.get<int64_t>(), g.last_seen = r.get<int64_t>();
    g.observations = r.get<int32_t>();
    g.alive = r.get<uint8_t>() != 0;
    if (version >= 2)
      for (int32_t x : r.get_vector<int32_t>()) {
        if (x < 1 || uint64_t(x) > n) throw std::runtime_error(r.what() + ": plane id out of range in a seen-apart list");
        g.apart.push_back(x);
      }
    if (version >= 3) {
      g.same_plane_distance = r.get<float>();
      if (!(g.same_plane_distance > 0 && std::isfinite(g.same_plane_distance)))
        throw std::runtime_error(r.what() + ": plane tolerance is not positive");
      const auto bridges = r.get<uint64_t>();
      if (bridges > r.remaining()) throw std::runtime_error(r.what() + ": corrupt bridged list");
      for (uint64_t k = 0; k < bridges; ++k) {
        const auto other = r.get<int32_t>();
        const auto frame = r.get<int64_t>();
        if (other < 1 || uint64_t(other) > n) throw std::runtime_error(r.what() + ": plane id out of range in a bridged list");
        g.bridged.emplace_back(other, frame);
      }
    }  // older snapshots: the segmenter's 1 cm floor (the tightest) and no bridges
    if (g.id != int(i) + 1) throw std::runtime_error(r.what() + ": plane ids are not 1..n");
    t.planes_.push_back(std::move(g));
  }
  const auto parent = r.get_vector<int32_t>();
  if (parent.size() != t.planes_.size() + 1) throw std::runtime_error(r.what() + ": union-find table size mismatch");
  for (int32_t p : parent)
    if (p < 0 || size_t(p) > t.planes_.size()) throw std::runtime_error(r.what() + ": union-find entry out of range");
  t.parent_.assign(parent.begin(), parent.end());
}

void PlaneStateIo::read(io::ByteReader& r, PlaneIdentifier& id) {
  const auto version = r.get<uint32_t>();
  if (version < 1 || version > 3)
    throw std::runtime_error(r.what() + ": unsupported plane state version " + std::to_string(version));
  id.window_ = r.get<int64_t>();
  read_table(r, id.table_, version);
  ReflectiveVote& v = id.vote_;
  v.history_.clear();
  const auto hn = r.get<uint64_t>();
  if (hn > r.remaining()) throw std::runtime_error(r.what() + ": corrupt vote history");
  for (uint64_t i = 0; i < hn; ++i) {
    const int plane = r.get<int32_t>();
    const auto len = r.get<uint64_t>();
    if (len > r.remaining()) throw std::runtime_error(r.what() + ": corrupt vote history");
    auto& hist = v.history_[plane];
    for (uint64_t j = 0; j < len; ++j) {
      const auto window = r.get<int64_t>();
      const bool outcome = r.get<uint8_t>() != 0;
      hist.emplace_back(window, outcome);
    }
  }
  const auto lookup = r.get_vector<int32_t>();
  v.lookup_ = std::set<int>(lookup.begin(), lookup.end());
}

}  // namespace rrg
