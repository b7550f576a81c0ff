#include "core/slam/mapper.h"
#include "core/slam/mirror_depth.h"
#include "core/slam/reflection_stereo.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

namespace rrg {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

constexpr float kDepthUnits = 5000.0f;  // stored depth steps per metre

uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

template <class T>
DeviceImage<T> clone(const DeviceImage<T>& im) {
  DeviceImage<T> out(im.width(), im.height(), im.device());
  mem::copy(out.buffer().data(), im.device(), im.buffer().data(), im.device(), im.buffer().size() * sizeof(T));
  return out;
}

DeviceImage<float> mask_to_float(const DeviceImage<uint8_t>& m, const Device& device) {
  const Image<uint8_t> h = m.to_host();
  Image<float> f(h.width(), h.height());
  for (size_t i = 0; i < h.size(); ++i) f[i] = h[i] ? 1.0f : 0.0f;
  return DeviceImage<float>::from_host(f, device);
}

// Pass-1 results as the renderer takes them (R = R_raw > 0.5 as 0 / 1).
RaycastInputs to_inputs(RaycastResult&& r, const Device& device) {
  RaycastInputs in;
  in.R = mask_to_float(r.reflection_mask, device);
  in.C_t = std::move(r.colors);
  in.D_t = std::move(r.depth);
  in.I = std::move(r.plane_ids);
  return in;
}

RaycastInputs copy_inputs(const RaycastResult& r, const Device& device) {
  RaycastInputs in;
  in.R = mask_to_float(r.reflection_mask, device);
  in.C_t = clone(r.colors);
  in.D_t = clone(r.depth);
  in.I = clone(r.plane_ids);
  return in;
}

void append_to(GaussianSet& set, GaussianAdam& adam, const GaussianHost& batch) {
  if (batch.size() == 0) return;
  set.append(batch);
  adam.grow(set.size());
}

// Ids the table has merged into another instance (remap[l] is a positive id other than l). Merges
// are permanent, so the count only grows, and it grows exactly when a merge happened.
size_t absorbed_ids(std::span<const int32_t> remap) {
  size_t n = 0;
  for (size_t l = 0; l < remap.size(); ++l) n += remap[l] > 0 && remap[l] != int32_t(l);
  return n;
}

// Moves Gaussians of planes the table has merged away to the canonical id (remap); returns how
// many of the set's distinct plane ids moved (0: nothing is written).
int relabel_planes(GaussianSet& set, std::span<const int32_t> remap) {
  if (set.size() == 0 || remap.empty()) return 0;
  int moved = 0;
  for (const int32_t l : distinct_planes(set))
    if (size_t(l) < remap.size() && remap[size_t(l)] > 0 && remap[size_t(l)] != l) ++moved;
  if (moved > 0) set.remap_plane_ids(remap);
  return moved;
}

int64_t prune_set(GaussianSet& set, GaussianAdam& adam, const PruneParams& p) {
  const std::vector<uint8_t> keep = prune_mask(set, p);
  const size_t before = set.size();
  if (std::all_of(keep.begin(), keep.end(), [](uint8_t k) { return k != 0; })) return 0;
  const Compaction c = set.prune(keep);
  adam.compact(c);
  return int64_t(before - set.size());
}

}  // namespace

CompactFrame CompactFrame::from(const MappingFrame& frame) {
  CompactFrame s;
  s.index = frame.index;
  s.T_wc = frame.T_wc;
  s.width = frame.color.width();
  s.height = frame.color.height();
  s.rgb.resize(frame.color.size() * 3);
  s.depth.resize(frame.depth.size());
  for (size_t i = 0; i < frame.color.size(); ++i)
    for (int c = 0; c < 3; ++c)
      s.rgb[3 * i + c] = uint8_t(std::lround(std::clamp(frame.color[i][c], 0.0f, 1.0f) * 255.0f));
  for (size_t i = 0; i < frame.depth.size(); ++i) {
    const float d = frame.depth[i];
    s.depth[i] = (d > 0 && std::isfinite(d)) ? uint16_t(std::min(std::lround(d * kDepthUnits), 65535l)) : 0;
  }
  return s;
}

ColorImage CompactFrame::color() const {
  ColorImage c(width, height);
  for (size_t i = 0; i < c.size(); ++i) c[i] = Color(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]) / 255.0f;
  return c;
}

DepthImage CompactFrame::depth_m() const {
  DepthImage d(width, height);
  for (size_t i = 0; i < d.size(); ++i) d[i] = float(depth[i]) / kDepthUnits;
  return d;
}

// A selected frame for one step: ground truth on the host and the device, pass 1 at its pose.
struct GaussianMapper::StepFrame {
  const StoredFrame* frame = nullptr;
  bool local = false;
  ColorImage C_gt_host;
  DepthImage D_gt_host;
  DeviceImage<Color> C_gt;
  DeviceImage<float> D_gt;
  RaycastInputs rc;
  Image<float> C_var;  // host, for reflection densification
  Image<uint8_t> R;
  Image<int32_t> I_host;  // plane ids on the host: local frames (densification), all frames with the plane sweep
  bool shows_reflection = true;  // some pixel's I(u) is the plane of a reflection Gaussian
};

GaussianMapper::GaussianMapper(const MapperParams& params, const Intrinsics& K, const Device& device)
    : params_(params),
      K_(K),
      device_(device),
      base_(params.sh_degree, device),
      refl_(params.sh_degree, device),
      no_reflection_(params.sh_degree, device),
      adam_base_(params.adam_base, params.sh_degree, device),
      adam_refl_(params.adam_reflection, params.sh_degree, device),
      renderer_(device, params.render),
      query_renderer_(device, params.render) {
  params_.validate();
  if (!K.valid()) throw std::invalid_argument("GaussianMapper: invalid intrinsics " + K.to_string());
  publish();
}

void GaussianMapper::add_frame(MappingFrame frame, bool keyframe) {
  if (frame.color.width() != K_.width || frame.color.height() != K_.height || !frame.depth.same_size(frame.color))
    throw std::invalid_argument("GaussianMapper::add_frame: frame " + std::to_string(frame.index) + " is " +
                                std::to_string(frame.color.width()) + "x" + std::to_string(frame.color.height()) +
                                " (depth " + std::to_string(frame.depth.width()) + "x" +
                                std::to_string(frame.depth.height()) + "), the mapper expects " + K_.to_string());
  auto s = std::make_shared<StoredFrame>(CompactFrame::from(frame));
  std::lock_guard lock(frames_mutex_);
  recent_.push_back(s);
  if (keyframe) keyframes_.push_back(s);
}

size_t GaussianMapper::queued_frames() const {
  std::lock_guard lock(frames_mutex_);
  return recent_.size();
}

size_t GaussianMapper::keyframes() const {
  std::lock_guard lock(frames_mutex_);
  return keyframes_.size();
}

// N_local evenly spaced over the recent frames (the newest included), then N_global distinct random
// keyframes not already chosen. The recent frames are consumed.
std::vector<std::shared_ptr<const GaussianMapper::StoredFrame>> GaussianMapper::select_frames(uint64_t seed) {
  std::lock_guard lock(frames_mutex_);
  std::vector<std::shared_ptr<const StoredFrame>> out;
  const size_t n = recent_.size(), L = size_t(params_.n_local);
  if (n > 0 && L > 0) {
    if (n <= L) {
      out.assign(recent_.begin(), recent_.end());
    } else {
      for (size_t j = 0; j < L; ++j) out.push_back(recent_[(j + 1) * n / L - 1]);
    }
  }
  recent_.clear();
  std::vector<size_t> pool;
  for (size_t i = 0; i < keyframes_.size(); ++i)
    if (std::none_of(out.begin(), out.end(), [&](const auto& f) { return f.get() == keyframes_[i].get(); }))
      pool.push_back(i);
  std::mt19937_64 rng(seed);
  for (int g = 0; g < params_.n_global && !pool.empty(); ++g) {
    const size_t k = size_t(rng() % pool.size());
    out.push_back(keyframes_[pool[k]]);
    pool.erase(pool.begin() + std::ptrdiff_t(k));
  }
  return out;
}

// A step's frames with pass 1 at each, ready for run(); the selected frames are kept alive here.
struct GaussianMapper::Prepared {
  uint64_t step = 0;  // 1-based
  uint64_t seed = 0;
  std::vector<std::shared_ptr<const StoredFrame>> selected;
  std::vector<StepFrame> frames;
  double ms_raycast = 0;
};

std::shared_ptr<GaussianMapper::Prepared> GaussianMapper::prepare(const MappingContext& ctx) {
  if (!ctx.raycast) throw std::invalid_argument("GaussianMapper::prepare: the context has no raycast function");
  auto p = std::make_shared<Prepared>();
  size_t n_local = 0;
  {
    std::lock_guard lock(frames_mutex_);
    const int64_t newest = recent_.empty() ? -1 : recent_.back()->index;
    p->step = ++steps_;
    p->seed = mix(params_.seed ^ mix(p->step) ^ mix(uint64_t(newest) * 0x100000001b3ull));
    n_local = std::min(recent_.size(), size_t(params_.n_local));
  }
  p->selected = select_frames(p->seed);

  // 1. pass 1 and ground truth of every selected frame
  const auto t0 = Clock::now();
  p->frames.resize(p->selected.size());
  for (size_t i = 0; i < p->selected.size(); ++i) {
    StepFrame& f = p->frames[i];
    f.frame = p->selected[i].get();
    f.local = i < n_local;
    f.C_gt_host = f.frame->color();
    f.D_gt_host = f.frame->depth_m();
    f.C_gt = DeviceImage<Color>::from_host(f.C_gt_host, device_);
    f.D_gt = DeviceImage<float>::from_host(f.D_gt_host, device_);
    RaycastResult r = ctx.raycast(K_, f.frame->T_wc);
    if (r.depth.width() != K_.width || r.depth.height() != K_.height)
      throw std::runtime_error("GaussianMapper::prepare: the raycast returned images of the wrong size");
    if (f.local) {
      f.C_var = r.color_variance.to_host();
      f.R = r.reflection_mask.to_host();
    }
    f.rc = to_inputs(std::move(r), device_);
  }
  p->ms_raycast = ms_since(t0);
  return p;
}

MappingStats GaussianMapper::step(const MappingContext& ctx) { return run(prepare(ctx), ctx); }

MappingStats GaussianMapper::run(std::shared_ptr<Prepared> prepared, const MappingContext& ctx) {
  if (!prepared) throw std::invalid_argument("GaussianMapper::run: no prepared step");
  if (ctx.iterations < 0) throw std::invalid_argument("GaussianMapper::run: the context asks for a negative number of iterations");
  std::lock_guard step_lock(step_mutex_);
  const auto t_start = Clock::now();
  MappingStats st;
  st.ms_raycast = prepared->ms_raycast;
  const uint64_t seed = prepared->seed;
  std::vector<StepFrame>& frames = prepared->frames;
  if (frames.empty()) {
    publish();
    st.ms_total = ms_since(t_start) + st.ms_raycast;
    return st;
  }

  // 1b. The plane table merges instances (the lower id absorbs the higher), and the raycasts give
  // I(u) as canonical ids; a reflection Gaussian still carrying an absorbed id l would never again
  // meet a pixel with I(u) = l in the grouped pass 3: no colour, no gradient, never pruned.
  auto t0 = Clock::now();
  // Only after a new merge: Gaussians densified since the last one carry canonical ids already, and
  // listing the set's planes copies and sorts every id.
  if (const size_t absorbed = absorbed_ids(ctx.remap); absorbed != remap_absorbed_) {
    st.planes_relabelled = relabel_planes(refl_, ctx.remap);
    remap_absorbed_ = absorbed;
  }

  // 2. densification on the local frames
  const bool reflections = params_.reflections && !ctx.planes.empty();
  if (reflections && params_.densify.reflection_stereo_depth)
    for (StepFrame& f : frames) f.I_host = f.rc.I.to_host();
  RenderOutputs out;
  for (StepFrame& f : frames) {
    if (!f.local) continue;
    renderer_.render({K_, f.frame->T_wc}, base_, refl_, f.rc, out);
    const ColorImage C = out.C.to_host(), C_b = out.C_b.to_host();
    const Image<float> W_b = out.W_g.to_host(), W_r = out.W_r.to_host();
    if (f.I_host.empty()) f.I_host = f.rc.I.to_host();
    const Image<int32_t>& I = f.I_host;
    DensifyView v;
    v.K = K_;
    v.T_wc = f.frame->T_wc;
    v.C_gt = &f.C_gt_host;
    v.D_gt = &f.D_gt_host;
    v.C = &C;
    v.C_b = &C_b;
    v.W_b = &W_b;
    v.W_r = &W_r;
    v.R = &f.R;
    v.C_var = &f.C_var;
    v.I = &I;
    const uint64_t fseed = mix(seed ^ mix(uint64_t(f.frame->index)));
    const uint64_t rseed = mix(fseed);  // densify_reflection's
    Image<float> virtual_depth;
    if (reflections && params_.densify.reflection_mirrored_depth) {
      virtual_depth = mirrored_depth(ctx.raycast, K_, f.frame->T_wc, I, ctx.planes);
      v.virtual_depth = &virtual_depth;
    }
    if (reflections && params_.densify.reflection_stereo_depth) {
      // the plane sweep where the mirrored surface is not known, over the pixels that will be sampled
      MaskImage want = reflection_candidates(v, ctx.planes, params_.densify, rseed);
      if (!virtual_depth.empty())
        for (size_t i = 0; i < want.size(); ++i) want[i] = want[i] && !(virtual_depth[i] > 0);
      std::vector<StereoView> others;
      for (const StepFrame& g : frames)
        if (&g != &f) others.push_back({g.frame->T_wc, &g.C_gt_host, &g.I_host});
      const Image<float> swept = reflection_stereo_depth(K_, f.frame->T_wc, f.C_gt_host, I, &want, ctx.planes, others,
                                                         params_.reflection_stereo);
      if (virtual_depth.empty()) {
        virtual_depth = swept;
      } else {
        for (size_t i = 0; i < swept.size(); ++i)
          if (!(virtual_depth[i] > 0)) virtual_depth[i] = swept[i];
      }
      v.virtual_depth = &virtual_depth;
    }
    // New Gaussians start with the DC band only: the batches carry degree 0 and append() zeroes the
    // higher bands on the device (a degree-3 host batch is 240 bytes a Gaussian, 180 of them zeros).
    constexpr int kNewShDegree = 0;
    const GaussianHost nb = densify_base(v, params_.densify, kNewShDegree, fseed,
                                         reflections ? std::span<const ReflectivePlane>(ctx.planes) : std::span<const ReflectivePlane>{});
    append_to(base_, adam_base_, nb);
    st.base_added += int64_t(nb.size());
    if (reflections) {
      const GaussianHost nr = densify_reflection(v, ctx.planes, params_.densify, kNewShDegree, rseed);
      append_to(refl_, adam_refl_, nr);
      st.reflection_added += int64_t(nr.size());
    }
  }
  st.ms_densify = ms_since(t0);

  // 3. optimisation: a seeded shuffle of the selected frames, cycled. With the grouped pass 3, a
  // frame whose plane-id map shows none of the reflection Gaussians' planes is rendered with an
  // empty reflection set: C_r = 0, W_r = 0 and zero reflection gradients either way (Adam leaves
  // Gaussians without gradient as they are), without projecting, binning and walking all of them.
  t0 = Clock::now();
  if (params_.render.variant != ReflectionVariant::NoPlaneGrouping && refl_.size() > 0) {
    const std::vector<int32_t> planes = distinct_planes(refl_);
    for (StepFrame& f : frames) {
      if (f.I_host.empty()) f.I_host = f.rc.I.to_host();
      f.shows_reflection = shows_any_plane(f.I_host, planes);
    }
  }
  std::vector<size_t> order(frames.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::mt19937_64 rng(mix(seed));
  for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[size_t(rng() % i)]);
  const LossWeights lw = params_.loss_weights();
  RenderUpstream up;
  double loss_sum = 0;
  const int iterations = ctx.iterations > 0 ? ctx.iterations : params_.iterations;
  for (int it = 0; it < iterations; ++it) {
    StepFrame& f = frames[order[size_t(it) % order.size()]];
    const bool pass3 = refl_.size() > 0 && f.shows_reflection;
    if (refl_.size() > 0 && !pass3) ++st.reflection_skipped;
    auto tp = Clock::now();
    renderer_.render({K_, f.frame->T_wc}, base_, pass3 ? refl_ : no_reflection_, f.rc, out);
    st.optimise.render += ms_since(tp);
    tp = Clock::now();
    // The reflection terms where pass 3 ran: without it C_r = 0 and no reflection Gaussian gets a
    // gradient, so the Sobel term has nothing to act on and λ_rb would darken C_b with nothing to
    // take its place.
    const ReflectionImages refl_images{out.C_r, out.C_b, f.rc.R};
    const bool with_refl = reflections && pass3;
    const LossValues L = mapping_loss(out.C, f.C_gt, out.D_b, f.D_gt, with_refl ? &refl_images : nullptr, lw, up.v_C,
                                      up.v_D_b, up.v_C_r, loss_scratch_);
    loss_sum += L.total;
    st.optimise.loss += ms_since(tp);
    tp = Clock::now();
    renderer_.backward(up, v_base_, pass3 ? v_refl_ : v_no_reflection_);
    st.optimise.backward += ms_since(tp);
    tp = Clock::now();
    adam_base_.step(base_, v_base_);
    if (pass3) adam_refl_.step(refl_, v_refl_);
    st.optimise.adam += ms_since(tp);
  }
  st.iterations = iterations;
  st.frames = int(frames.size());
  st.loss = iterations > 0 ? loss_sum / iterations : 0.0;
  st.ms_optimise = ms_since(t0);

  // 4. pruning
  t0 = Clock::now();
  st.base_pruned = prune_set(base_, adam_base_, params_.prune_base);
  st.reflection_pruned = prune_set(refl_, adam_refl_, params_.prune_reflection);
  st.ms_prune = ms_since(t0);
  st.base_size = int64_t(base_.size());
  st.reflection_size = int64_t(refl_.size());

  publish();
  st.ms_total = ms_since(t_start) + st.ms_raycast;  // pass 1 included, on whichever thread it ran
  if (st.planes_relabelled > 0)
    spdlog::debug("mapping step {}: reflection Gaussians of {} merged plane(s) moved to the canonical id",
                  prepared->step, st.planes_relabelled);
  spdlog::debug("mapping step {}: {} frames, +{} / -{} base ({}), +{} / -{} reflection ({}; pass 3 skipped in {} of {} "
                "iterations), loss {:.4f}, {:.1f} ms (raycast {:.1f}, densify {:.1f}, optimise {:.1f}, prune {:.1f})",
                prepared->step, st.frames, st.base_added, st.base_pruned, st.base_size, st.reflection_added,
                st.reflection_pruned, st.reflection_size, st.reflection_skipped, st.iterations, st.loss, st.ms_total,
                st.ms_raycast, st.ms_densify, st.ms_optimise, st.ms_prune);
  return st;
}

void GaussianMapper::publish() {
  // Device-to-device copies (no round trip through the host, which on CUDA crossed PCIe twice) into
  // the snapshot before the current one when no reader holds it any more: its buffers are reused,
  // so a step publishes without allocating (tens of MB, page-faulted in anew on the CPU each time).
  std::shared_ptr<MapSnapshot> snap;
  {
    std::lock_guard lock(snapshot_mutex_);
    snap = std::move(spare_);
  }
  // No other owner can appear: spare_ is never handed out. The fence orders the last reader's
  // release (its reference count decrement) before our writes.
  const bool reusable = snap && snap.use_count() == 1 && snap->base.sh_degree() == base_.sh_degree() &&
                        snap->reflection.sh_degree() == refl_.sh_degree() && snap->base.device() == device_;
  if (reusable) {
    std::atomic_thread_fence(std::memory_order_acquire);
    snap->base.assign(base_);
    snap->reflection.assign(refl_);
    snap->reflection_planes = distinct_planes(refl_);
  } else {
    snap = std::make_shared<MapSnapshot>(MapSnapshot{base_.copy(), refl_.copy(), 0, distinct_planes(refl_)});
  }
  std::lock_guard lock(snapshot_mutex_);
  snap->version = ++version_;
  spare_ = std::move(snapshot_);
  snapshot_ = std::move(snap);
}

std::shared_ptr<const MapSnapshot> GaussianMapper::snapshot() const {
  std::lock_guard lock(snapshot_mutex_);
  return snapshot_;
}

void GaussianMapper::render(const RenderCamera& cam, const RaycastResult& raycast, RenderOutputs& out) const {
  const auto snap = snapshot();
  const RaycastInputs in = copy_inputs(raycast, device_);
  std::lock_guard lock(render_mutex_);
  query_renderer_.render(cam, snap->base, snap->reflection, in, out);
}

ColorImage GaussianMapper::render_reflection(const RenderCamera& cam, const DeviceImage<int32_t>& I,
                                             float stop_mean) const {
  const auto snap = snapshot();
  if (params_.render.variant != ReflectionVariant::NoPlaneGrouping && !shows_any_plane(I.to_host(), snap->reflection_planes))
    return ColorImage(cam.K.width, cam.K.height, Color::Zero());  // what pass 3 would draw: nothing
  RenderOutputs out;
  std::lock_guard lock(render_mutex_);
  query_renderer_.render_reflection(cam, snap->reflection, I, out, stop_mean);
  return out.C_r.to_host();
}

GaussianHost GaussianMapper::base_host() const { return snapshot()->base.to_host(); }
GaussianHost GaussianMapper::reflection_host() const { return snapshot()->reflection.to_host(); }

void GaussianMapper::load(const GaussianHost& base, const GaussianHost& reflection) {
  std::lock_guard step_lock(step_mutex_);
  base_ = GaussianSet::from_host(base, device_);
  refl_ = GaussianSet::from_host(reflection, device_);
  adam_base_ = GaussianAdam(params_.adam_base, base.sh_degree, device_);
  adam_refl_ = GaussianAdam(params_.adam_reflection, reflection.sh_degree, device_);
  adam_base_.reset(base_.size());
  adam_refl_.reset(refl_.size());
  remap_absorbed_ = 0;  // the loaded ids may predate any merge the next step's table shows
  publish();
}

MapperState GaussianMapper::export_state() const {
  std::lock_guard step_lock(step_mutex_);
  MapperState st;
  st.adam_base = adam_base_.to_host();
  st.adam_reflection = adam_refl_.to_host();
  std::lock_guard lock(frames_mutex_);
  st.steps = steps_;
  std::vector<const StoredFrame*> seen;  // a frame is both recent and a keyframe until the next step
  const auto index_of = [&](const std::shared_ptr<const StoredFrame>& f) {
    const auto it = std::find(seen.begin(), seen.end(), f.get());
    if (it != seen.end()) return uint32_t(it - seen.begin());
    seen.push_back(f.get());
    st.frames.push_back(*f);
    return uint32_t(seen.size() - 1);
  };
  for (const auto& f : keyframes_) st.keyframes.push_back(index_of(f));
  for (const auto& f : recent_) st.recent.push_back(index_of(f));
  return st;
}

void GaussianMapper::import_state(MapperState st) {
  std::lock_guard step_lock(step_mutex_);
  if (st.adam_base.steps.size() != base_.size() || st.adam_reflection.steps.size() != refl_.size())
    throw std::invalid_argument("GaussianMapper::import_state: Adam state for " + std::to_string(st.adam_base.steps.size()) +
                                " + " + std::to_string(st.adam_reflection.steps.size()) + " Gaussians, the map has " +
                                std::to_string(base_.size()) + " + " + std::to_string(refl_.size()));
  std::vector<std::shared_ptr<const StoredFrame>> frames;
  for (CompactFrame& f : st.frames) {
    if (f.width != K_.width || f.height != K_.height || f.rgb.size() != size_t(f.width) * f.height * 3 ||
        f.depth.size() != size_t(f.width) * f.height)
      throw std::invalid_argument("GaussianMapper::import_state: frame " + std::to_string(f.index) + " is " +
                                  std::to_string(f.width) + "x" + std::to_string(f.height) + ", the mapper expects " +
                                  K_.to_string());
    frames.push_back(std::make_shared<const StoredFrame>(std::move(f)));
  }
  const auto pick = [&](const std::vector<uint32_t>& ids, auto& out) {
    for (const uint32_t i : ids) {
      if (i >= frames.size())
        throw std::invalid_argument("GaussianMapper::import_state: frame reference " + std::to_string(i) + " of " +
                                    std::to_string(frames.size()));
      out.push_back(frames[i]);
    }
  };
  std::vector<std::shared_ptr<const StoredFrame>> keyframes;
  std::deque<std::shared_ptr<const StoredFrame>> recent;
  pick(st.keyframes, keyframes);
  pick(st.recent, recent);
  GaussianAdam adam_base(params_.adam_base, base_.sh_degree(), device_), adam_refl(params_.adam_reflection, refl_.sh_degree(), device_);
  adam_base.from_host(st.adam_base);
  adam_refl.from_host(st.adam_reflection);
  adam_base_ = std::move(adam_base);
  adam_refl_ = std::move(adam_refl);
  std::lock_guard lock(frames_mutex_);
  steps_ = st.steps;
  keyframes_ = std::move(keyframes);
  recent_ = std::move(recent);
}

}  // namespace rrg
