#include "core/gaussians/gaussian_set.h"

#include "core/common/dispatch.h"
#include "core/gaussians/gaussian_set_impl.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rrg {

namespace {

void check_degree(int degree) {
  if (degree < 0 || degree > kMaxShDegree)
    throw std::invalid_argument("GaussianSet: SH degree " + std::to_string(degree) + " outside [0, 3]");
}

// Copies count elements of host data to dst[offset...] on dst's device.
template <class T>
void upload(Buffer<T>& dst, size_t offset, const std::vector<T>& host) {
  mem::copy(dst.data() + offset, dst.device(), host.data(), Device::cpu(), host.size() * sizeof(T));
}

template <class T>
void download(const Buffer<T>& src, size_t count, std::vector<T>& host) {
  host.resize(count);
  mem::copy(host.data(), Device::cpu(), src.data(), src.device(), count * sizeof(T));
}

// New buffer of `capacity` elements holding the first `keep` elements of b.
template <class T>
void regrow(Buffer<T>& b, size_t capacity, size_t keep, const Device& device) {
  Buffer<T> grown(capacity, device);
  mem::copy(grown.data(), device, b.data(), device, keep * sizeof(T));
  b = std::move(grown);
}

template <class T>
Span<uint32_t> words_of(Buffer<T>& b) {
  static_assert(sizeof(T) % 4 == 0);
  return {reinterpret_cast<uint32_t*>(b.data()), int64_t(b.size() * sizeof(T) / 4)};
}

}  // namespace

void GaussianHost::resize(size_t n) {
  means.resize(n, Eigen::Vector3f::Zero());
  log_scales.resize(n, Eigen::Vector3f::Zero());
  quats.resize(n, Eigen::Vector4f(1, 0, 0, 0));
  logit_opacities.resize(n, 0.0f);
  sh.resize(n * size_t(sh_coeffs()), Eigen::Vector3f::Zero());
  plane_ids.resize(n, 0);
}

void GaussianHost::validate() const {
  check_degree(sh_degree);
  const size_t n = means.size();
  auto need = [&](size_t got, size_t want, const char* name) {
    if (got != want)
      throw std::invalid_argument(std::string("GaussianHost: ") + name + " has " + std::to_string(got) +
                                  " entries, expected " + std::to_string(want));
  };
  need(log_scales.size(), n, "log_scales");
  need(quats.size(), n, "quats");
  need(logit_opacities.size(), n, "logit_opacities");
  need(sh.size(), n * size_t(sh_coeffs()), "sh");
  need(plane_ids.size(), n, "plane_ids");
}

GaussianSet::GaussianSet(int sh_degree, const Device& device, size_t capacity)
    : sh_degree_(sh_degree), device_(device) {
  check_degree(sh_degree);
  reserve(capacity);
}

GaussianSet GaussianSet::from_host(const GaussianHost& host, const Device& device) {
  GaussianSet set(host.sh_degree, device, host.size());
  set.append(host);
  return set;
}

GaussianHost GaussianSet::to_host() const {
  GaussianHost h(sh_degree_);
  download(means_, size_, h.means);
  download(log_scales_, size_, h.log_scales);
  download(quats_, size_, h.quats);
  download(logit_opacities_, size_, h.logit_opacities);
  download(sh_, size_ * size_t(sh_coeffs()), h.sh);
  download(plane_ids_, size_, h.plane_ids);
  return h;
}

GaussianSet GaussianSet::copy() const {
  GaussianSet out(sh_degree_, device_, size_);
  out.assign(*this);
  return out;
}

void GaussianSet::assign(const GaussianSet& src) {
  if (&src == this) return;
  if (src.sh_degree_ != sh_degree_ || !(src.device_ == device_))
    throw std::invalid_argument("GaussianSet::assign: the source has SH degree " + std::to_string(src.sh_degree_) +
                                " on " + src.device_.to_string() + ", this set " + std::to_string(sh_degree_) + " on " +
                                device_.to_string());
  size_ = 0;  // nothing to keep: reserve() then regrows without copying
  if (src.size_ > capacity_) reserve(std::max(src.size_, src.capacity_));  // grows as the source grew
  const auto same = [&](auto& dst, const auto& from, size_t count) {
    mem::copy(dst.data(), device_, from.data(), device_, count * sizeof(*from.data()));
  };
  same(means_, src.means_, src.size_);
  same(log_scales_, src.log_scales_, src.size_);
  same(quats_, src.quats_, src.size_);
  same(logit_opacities_, src.logit_opacities_, src.size_);
  same(sh_, src.sh_, src.size_ * size_t(sh_coeffs()));
  same(plane_ids_, src.plane_ids_, src.size_);
  size_ = src.size_;
}

void GaussianSet::reserve(size_t n) {
  if (n <= capacity_) return;
  const size_t k = size_t(sh_coeffs());
  regrow(means_, n, size_, device_);
  regrow(log_scales_, n, size_, device_);
  regrow(quats_, n, size_, device_);
  regrow(logit_opacities_, n, size_, device_);
  regrow(sh_, n * k, size_ * k, device_);
  regrow(plane_ids_, n, size_, device_);
  capacity_ = n;
}

void GaussianSet::append(const GaussianHost& batch) {
  batch.validate();
  if (batch.sh_degree > sh_degree_)
    throw std::invalid_argument("GaussianSet::append: batch SH degree " + std::to_string(batch.sh_degree) +
                                " > set SH degree " + std::to_string(sh_degree_));
  const size_t n = size_ + batch.size();
  if (n > capacity_) reserve(std::max(n, capacity_ + capacity_ / 2));
  const size_t k = size_t(sh_coeffs());
  upload(means_, size_, batch.means);
  upload(log_scales_, size_, batch.log_scales);
  upload(quats_, size_, batch.quats);
  upload(logit_opacities_, size_, batch.logit_opacities);
  if (batch.sh_degree == sh_degree_) {
    upload(sh_, size_ * k, batch.sh);
  } else if (batch.size() > 0) {
    // Only the batch's bands travel; the higher ones are zeroed where they land.
    const auto src = Buffer<Eigen::Vector3f>::from_host(batch.sh, device_);
    const Span<Eigen::Vector3f> dst{sh_.data() + size_ * k, int64_t(batch.size() * k)};
    const int from = batch.sh_coeffs(), to = int(k);
    const int64_t m = int64_t(batch.size());
    RRG_DISPATCH(device_, kernel::pad_sh_rows_cpu(dst, to, src.span(), from, m),
                 kernel::pad_sh_rows_cuda(dst, to, src.span(), from, m));
  }
  upload(plane_ids_, size_, batch.plane_ids);
  size_ = n;
}

void GaussianSet::remap_plane_ids(std::span<const int32_t> remap) {
  if (size_ == 0 || remap.empty()) return;
  const auto table = Buffer<int32_t>::from_host(remap, device_);
  RRG_DISPATCH(device_, kernel::remap_ids_cpu(plane_ids(), table.span()), kernel::remap_ids_cuda(plane_ids(), table.span()));
}

Compaction GaussianSet::prune(const std::vector<uint8_t>& keep) {
  if (keep.size() != size_)
    throw std::invalid_argument("GaussianSet::prune: keep mask has " + std::to_string(keep.size()) +
                                " entries for " + std::to_string(size_) + " Gaussians");
  Compaction c;
  c.old_size = size_;
  c.new_size = size_t(std::count_if(keep.begin(), keep.end(), [](uint8_t k) { return k != 0; }));
  // Holes before new_size are filled, in order, by survivors at or after new_size.
  size_t tail = c.new_size;
  for (size_t i = 0; i < c.new_size; ++i) {
    if (keep[i]) continue;
    while (!keep[tail]) ++tail;
    c.src.push_back(int32_t(tail++));
    c.dst.push_back(int32_t(i));
  }
  if (!c.src.empty()) {
    const int k = sh_coeffs();
    apply_compaction(c, words_of(means_), 3, device_);
    apply_compaction(c, words_of(log_scales_), 3, device_);
    apply_compaction(c, words_of(quats_), 4, device_);
    apply_compaction(c, words_of(logit_opacities_), 1, device_);
    apply_compaction(c, words_of(sh_), 3 * k, device_);
    apply_compaction(c, words_of(plane_ids_), 1, device_);
  }
  size_ = c.new_size;
  return c;
}

void apply_compaction(const Compaction& c, Span<uint32_t> data, int words, const Device& device) {
  if (words <= 0) throw std::invalid_argument("apply_compaction: words per Gaussian must be > 0");
  if (data.size < int64_t(c.old_size) * words)
    throw std::invalid_argument("apply_compaction: array holds " + std::to_string(data.size / words) +
                                " Gaussians, the compaction needs " + std::to_string(c.old_size));
  if (c.src.empty()) return;
  const auto src = Buffer<int32_t>::from_host(c.src, device);
  const auto dst = Buffer<int32_t>::from_host(c.dst, device);
  RRG_DISPATCH(device, kernel::move_words_cpu(data, words, src.span(), dst.span()),
               kernel::move_words_cuda(data, words, src.span(), dst.span()));
}

}  // namespace rrg
