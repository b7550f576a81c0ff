// Session snapshots (docs/slam.md "Snapshots"): one file, written atomically:
//   magic "RRGSESS\0", format version u32, payload size u64, FNV-1a 64 of the payload, payload.
// Payload v2 = the continuation section (its length, then core/slam/snapshot_continuation.h: the
// tracker's ORB keyframes and motion state, the mapper's step counter, stored keyframes, frames
// since the last step and both Adam states, the session's fused frames not yet handed to the
// mapper, the reflective fill's carried surfaces), followed by the v1 payload:
//   config (YAML text + category table), schedule counters and the last pose, trajectory and
//   per-frame reports, the TSDF (its own versioned file format, embedded), base and reflection
//   Gaussians, the plane identifier's state, the accepted reflective planes and the id remap.
// A v2 snapshot continues exactly as the uninterrupted session (sync mode, tested bit for bit on
// the CPU). v1 files still load: the map is the same, but the tracker resumes from the last pose
// with no keyframes and zero velocity, and the mapper from no keyframes and fresh Adam moments.
#include "core/io/atomic_file.h"
#include "core/io/byte_stream.h"
#include "core/planes/plane_state_io.h"
#include "core/slam/session_impl.h"
#include "core/slam/snapshot_continuation.h"
#include "core/tsdf/tsdf_io.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>

#include <unistd.h>

namespace rrg {
namespace {

constexpr char kMagic[8] = {'R', 'R', 'G', 'S', 'E', 'S', 'S', '\0'};
constexpr uint32_t kVersion = 2;  // 1: no continuation section (still read)

void put_floats(io::ByteWriter& w, const float* p, size_t n) {
  w.put<uint64_t>(n);
  for (size_t i = 0; i < n; ++i) w.put(p[i]);
}
std::vector<float> get_floats(io::ByteReader& r) { return r.get_vector<float>(); }

template <int N>
void put_vecs(io::ByteWriter& w, const std::vector<Eigen::Matrix<float, N, 1>>& v) {
  put_floats(w, v.empty() ? nullptr : v[0].data(), v.size() * N);
}
template <int N>
std::vector<Eigen::Matrix<float, N, 1>> get_vecs(io::ByteReader& r, size_t expect, const char* what) {
  const std::vector<float> f = get_floats(r);
  if (f.size() != expect * N) throw std::runtime_error(r.what() + ": Gaussian array '" + what + "' has the wrong length");
  std::vector<Eigen::Matrix<float, N, 1>> v(expect);
  for (size_t i = 0; i < expect; ++i)
    for (int k = 0; k < N; ++k) v[i][k] = f[i * N + k];
  return v;
}

void put_gaussians(io::ByteWriter& w, const GaussianHost& g) {
  w.put<int32_t>(g.sh_degree);
  w.put<uint64_t>(g.size());
  put_vecs<3>(w, g.means);
  put_vecs<3>(w, g.log_scales);
  put_vecs<4>(w, g.quats);
  w.put_vector(g.logit_opacities);
  put_vecs<3>(w, g.sh);
  w.put_vector(g.plane_ids);
}

GaussianHost get_gaussians(io::ByteReader& r) {
  const int degree = r.get<int32_t>();
  if (degree < 0 || degree > kMaxShDegree) throw std::runtime_error(r.what() + ": bad SH degree");
  GaussianHost g(degree);
  const auto n = r.get<uint64_t>();
  if (n > r.remaining()) throw std::runtime_error(r.what() + ": corrupt Gaussian count");
  g.means = get_vecs<3>(r, n, "means");
  g.log_scales = get_vecs<3>(r, n, "log_scales");
  g.quats = get_vecs<4>(r, n, "quats");
  g.logit_opacities = r.get_vector<float>();
  g.sh = get_vecs<3>(r, n * size_t(g.sh_coeffs()), "sh");
  g.plane_ids = r.get_vector<int32_t>();
  g.validate();
  return g;
}

std::vector<uint8_t> read_file(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + path.string());
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// The TSDF goes through its own file format (versioned, checksummed) via a temporary file.
std::vector<uint8_t> volume_bytes(const TsdfVolume& volume, const std::filesystem::path& beside) {
  const auto tmp = beside.parent_path() / (beside.filename().string() + ".tsdf-tmp");
  save_volume(volume, tmp);
  std::vector<uint8_t> bytes;
  try {
    bytes = read_file(tmp);
  } catch (...) {
    std::filesystem::remove(tmp);
    throw;
  }
  std::filesystem::remove(tmp);
  return bytes;
}

TsdfVolume volume_from_bytes(std::span<const uint8_t> bytes, const Device& device, const std::filesystem::path& beside,
                             const std::function<bool(const Eigen::Vector3i&)>& resident) {
  const auto tmp = std::filesystem::temp_directory_path() /
                   ("rrg-load-" + std::to_string(::getpid()) + "-" + beside.filename().string() + ".tsdf");
  {
    std::ofstream f(tmp, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!f) throw std::runtime_error("cannot write a temporary file " + tmp.string());
  }
  try {
    TsdfVolume v = load_volume(tmp, device, resident);
    std::filesystem::remove(tmp);
    return v;
  } catch (...) {
    std::filesystem::remove(tmp);
    throw;
  }
}

}  // namespace

void Session::save(const std::filesystem::path& file) const {
  Impl& s = *impl_;
  // A consistent cut: no mapping step running, no fusion (save runs on the session's worker or
  // with the worker idle; the volume lock keeps renders out while the TSDF is copied).
  s.worker.wait();
  io::ByteWriter w;
  size_t continuation_bytes = 0, stored_frames = 0;
  {
    ContinuationState c;
    c.tracker = s.tracker.export_state();
    c.mapper = s.mapper.export_state();
    for (size_t i = 0; i < s.pending.size(); ++i) {
      c.pending.push_back(CompactFrame::from(s.pending[i]));
      c.pending_keyframe.push_back(s.pending_keyframe[i] ? 1 : 0);
    }
    c.fill_regions = s.fill_regions;
    c.undecided_planes.assign(s.undecided.begin(), s.undecided.end());
    const std::vector<uint8_t> section = write_continuation(c);
    continuation_bytes = section.size();
    stored_frames = c.mapper.frames.size() + c.pending.size();
    w.put_bytes(section);
  }
  SessionConfig config = s.config;
  w.put_string(config_to_yaml(config));
  w.put<uint64_t>(config.categories.size());
  for (const auto& [id, name] : config.categories) w.put<uint16_t>(id), w.put_string(name);
  w.put<int64_t>(s.frames), w.put<int64_t>(s.fused), w.put<int64_t>(s.lost), w.put<int64_t>(s.last_index);
  io::put_pose(w, s.T_last);
  w.put<uint64_t>(s.map_version.load());
  {
    std::lock_guard lock(s.state_mutex);
    w.put<uint64_t>(s.reports.size());
    for (const FrameReport& r : s.reports) {
      w.put<int64_t>(r.index), w.put<double>(r.timestamp);
      io::put_pose(w, r.T_wc);
      w.put<int32_t>(int32_t(r.state)), w.put<uint8_t>(r.fused), w.put<uint8_t>(r.identified);
    }
    w.put<uint64_t>(s.reflective.size());
    for (const ReflectivePlane& p : s.reflective) {
      w.put<int32_t>(p.id);
      for (int k = 0; k < 4; ++k) w.put(p.plane[k]);
    }
    w.put_vector(s.remap);
    w.put<int64_t>(s.mapping.steps);
  }
  {
    std::shared_lock lock(s.volume_mutex);
    w.put_bytes(volume_bytes(s.volume, file));
  }
  put_gaussians(w, s.mapper.base_host());
  put_gaussians(w, s.mapper.reflection_host());
  PlaneStateIo::write(w, s.identifier);

  const std::vector<uint8_t>& payload = w.bytes();
  io::write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(kMagic, sizeof(kMagic));
    const uint32_t version = kVersion;
    const uint64_t size = payload.size(), sum = fnv1a64(payload);
    f.write(reinterpret_cast<const char*>(&version), sizeof(version));
    f.write(reinterpret_cast<const char*>(&size), sizeof(size));
    f.write(reinterpret_cast<const char*>(&sum), sizeof(sum));
    f.write(reinterpret_cast<const char*>(payload.data()), std::streamsize(payload.size()));
    f.flush();
    if (!f) throw std::runtime_error("session save: cannot write " + file.string());
  });
  spdlog::debug("session: saved {} frames, {} bytes ({} in the continuation section: {} stored frames, Adam state) -> {}",
                s.frames, payload.size(), continuation_bytes, stored_frames, file.string());
}

std::unique_ptr<Session> Session::load(const std::filesystem::path& file, std::unique_ptr<SemanticCue> cue) {
  const std::string what = "session snapshot " + file.string();
  const std::vector<uint8_t> bytes = read_file(file);
  constexpr size_t kHeader = sizeof(kMagic) + 4 + 8 + 8;
  if (bytes.size() < kHeader || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw std::runtime_error(what + ": not a session snapshot (bad magic)");
  uint32_t version;
  uint64_t size, sum;
  std::memcpy(&version, bytes.data() + 8, 4);
  std::memcpy(&size, bytes.data() + 12, 8);
  std::memcpy(&sum, bytes.data() + 20, 8);
  if (version != 1 && version != kVersion)
    throw std::runtime_error(what + ": unsupported version " + std::to_string(version));
  if (size != bytes.size() - kHeader) throw std::runtime_error(what + ": truncated (payload size mismatch)");
  const std::span<const uint8_t> payload(bytes.data() + kHeader, size);
  if (fnv1a64(payload) != sum) throw std::runtime_error(what + ": checksum mismatch (corrupt file)");

  io::ByteReader r(payload, what);
  const std::span<const uint8_t> continuation = version >= 2 ? r.get_bytes() : std::span<const uint8_t>{};
  SessionConfig config;
  {
    const std::string yaml = r.get_string();
    const auto tmp = std::filesystem::temp_directory_path() / ("rrg-config-" + std::to_string(::getpid()) + ".yaml");
    { std::ofstream(tmp) << yaml; }
    try {
      load_config_yaml(config, tmp);
    } catch (...) {
      std::filesystem::remove(tmp);
      throw;
    }
    std::filesystem::remove(tmp);
  }
  const auto ncat = r.get<uint64_t>();
  if (ncat > r.remaining()) throw std::runtime_error(what + ": corrupt category table");
  for (uint64_t i = 0; i < ncat; ++i) {
    const auto id = r.get<uint16_t>();
    config.categories[id] = r.get_string();
  }
  auto session = std::make_unique<Session>(config, std::move(cue));
  Impl& s = *session->impl_;
  s.frames = r.get<int64_t>(), s.fused = r.get<int64_t>(), s.lost = r.get<int64_t>(), s.last_index = r.get<int64_t>();
  s.T_last = io::get_pose(r);
  s.map_version = r.get<uint64_t>();
  const auto nrep = r.get<uint64_t>();
  if (nrep > r.remaining()) throw std::runtime_error(what + ": corrupt report count");
  for (uint64_t i = 0; i < nrep; ++i) {
    FrameReport rep;
    rep.index = r.get<int64_t>(), rep.timestamp = r.get<double>();
    rep.T_wc = io::get_pose(r);
    rep.state = TrackingState(std::clamp(r.get<int32_t>(), 0, 2));
    rep.fused = r.get<uint8_t>() != 0, rep.identified = r.get<uint8_t>() != 0;
    s.reports.push_back(rep);
    s.trajectory.push_back({rep.timestamp, rep.T_wc.cast<double>()});
  }
  if (!s.reports.empty()) s.state = s.reports.back().state;
  const auto nref = r.get<uint64_t>();
  if (nref > r.remaining()) throw std::runtime_error(what + ": corrupt plane list");
  for (uint64_t i = 0; i < nref; ++i) {
    ReflectivePlane p;
    p.id = r.get<int32_t>();
    for (int k = 0; k < 4; ++k) p.plane[k] = r.get<float>();
    s.reflective.push_back(p);
  }
  s.remap = r.get_vector<int32_t>();
  s.mapping.steps = r.get<int64_t>();
  // A session that streams loads its TSDF as the last fusion left it: the blocks beyond
  // tsdf.stream_radius of that camera in host memory, never in the device pool.
  std::function<bool(const Eigen::Vector3i&)> resident;
  const auto last_fused = std::find_if(s.reports.rbegin(), s.reports.rend(), [](const FrameReport& f) { return f.fused; });
  if (s.config.stream_radius > 0.0f && last_fused != s.reports.rend()) {
    const Eigen::Vector3f center = last_fused->T_wc.translation();
    const float radius = s.config.stream_radius;
    resident = [center, radius, voxel = s.config.tsdf.voxel_size](const Eigen::Vector3i& b) {
      return (block_center(b, voxel) - center).norm() <= radius;  // TsdfVolume::stream_out's test
    };
  }
  s.volume = volume_from_bytes(r.get_bytes(), config.device, file, resident);
  GaussianHost base = get_gaussians(r);
  GaussianHost refl = get_gaussians(r);
  s.mapping.base_gaussians = int64_t(base.size());
  s.mapping.reflection_gaussians = int64_t(refl.size());
  s.mapper.load(base, refl);
  PlaneStateIo::read(r, s.identifier);
  s.global_planes = s.identifier.table().live_ids().size();
  if (r.remaining() != 0) throw std::runtime_error(what + ": " + std::to_string(r.remaining()) + " unexpected trailing bytes");
  if (version >= 2) {
    ContinuationState c = read_continuation(continuation, what);
    s.tracker.import_state(c.tracker);
    try {
      s.mapper.import_state(std::move(c.mapper));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(what + ": " + e.what());
    }
    for (size_t i = 0; i < c.pending.size(); ++i) {
      if (c.pending[i].width != s.K.width || c.pending[i].height != s.K.height)
        throw std::runtime_error(what + ": pending frame " + std::to_string(c.pending[i].index) + " has the wrong size");
      s.pending.push_back(c.pending[i].expand());
      s.pending_keyframe.push_back(c.pending_keyframe[i] != 0);
    }
    s.mapping.queued = int64_t(s.pending.size());
    // Not stored: the frames since the last step are the pending ones (live: fewer if thinned).
    s.fused_at_step = s.fused - int64_t(s.pending.size());
    s.tracker_keyframes = s.tracker.keyframes().size();
    s.fill_regions = std::move(c.fill_regions);
    s.undecided = std::set<int>(c.undecided_planes.begin(), c.undecided_planes.end());
  } else {
    s.fused_at_step = s.fused;
    spdlog::info("{}: format v1 has no keyframes, motion or optimiser state; tracking resumes from the last pose "
                 "and mapping from the frames that follow", what);
    if (s.frames > 0) s.tracker.resume(s.T_last);
  }
  return session;
}

}  // namespace rrg
