#include "core/eval/image_set.h"

#include "core/eval/image_metrics.h"
#include "core/io/image_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace rrg::eval {
namespace fs = std::filesystem;
namespace {

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  static const std::set<std::string> kExtensions = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm"};
  return kExtensions.contains(ext);
}

bool is_list_file(const fs::path& p) { return p.extension() == ".txt"; }

bool is_number(const std::string& s) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && ptr == s.data() + s.size();
}

std::vector<fs::path> read_list(const fs::path& list) {
  std::ifstream in(list);
  if (!in) throw std::runtime_error("cannot open image list " + list.string());
  std::vector<fs::path> out;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    std::istringstream tokens(line);
    std::vector<std::string> words;
    for (std::string w; tokens >> w;) words.push_back(w);
    if (words.empty() || words[0][0] == '#') continue;
    std::string entry;
    if (words.size() == 1) entry = words[0];
    else if (words.size() == 2 && is_number(words[0])) entry = words[1];
    else
      throw std::runtime_error(list.string() + ":" + std::to_string(line_no) +
                               ": expected 'timestamp path' or 'path', got '" + line + "'");
    fs::path p = entry;
    if (p.is_relative()) p = list.parent_path() / p;
    if (!fs::is_regular_file(p))
      throw std::runtime_error(list.string() + ":" + std::to_string(line_no) + ": image not found: " + p.string());
    out.push_back(p);
  }
  if (out.empty()) throw std::runtime_error("image list " + list.string() + " names no images");
  return out;
}

std::map<std::string, fs::path> by_stem(const fs::path& folder) {
  std::map<std::string, fs::path> out;
  for (const fs::path& p : list_images(folder)) out.emplace(p.stem().string(), p);
  return out;
}

std::string join_some(const std::vector<std::string>& names) {
  constexpr size_t kShown = 5;
  std::string s;
  for (size_t i = 0; i < names.size() && i < kShown; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > kShown) s += " (and " + std::to_string(names.size() - kShown) + " more)";
  return s;
}

std::vector<std::string> keys_missing_from(const std::map<std::string, fs::path>& a,
                                           const std::map<std::string, fs::path>& b) {
  std::vector<std::string> out;
  for (const auto& [stem, path] : a)
    if (!b.contains(stem)) out.push_back(path.filename().string());
  return out;
}

}  // namespace

std::vector<fs::path> list_images(const fs::path& source) {
  if (!fs::exists(source)) throw std::runtime_error("image source not found: " + source.string());
  if (fs::is_regular_file(source)) {
    if (!is_list_file(source))
      throw std::runtime_error("image source " + source.string() + " is neither a folder nor a .txt list");
    return read_list(source);
  }
  if (!fs::is_directory(source)) throw std::runtime_error("image source " + source.string() + " is not a folder");
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(source))
    if (entry.is_regular_file() && is_image_file(entry.path())) out.push_back(entry.path());
  if (out.empty()) throw std::runtime_error("no image files in folder " + source.string());
  std::sort(out.begin(), out.end());
  for (size_t i = 1; i < out.size(); ++i)
    if (out[i].stem() == out[i - 1].stem())
      throw std::runtime_error("folder " + source.string() + " has two images named " + out[i].stem().string() +
                               ": " + out[i - 1].filename().string() + " and " + out[i].filename().string());
  return out;
}

std::vector<ImagePair> match_images(const fs::path& est, const fs::path& ref, const std::optional<fs::path>& mask) {
  const bool by_name = fs::is_directory(est) && fs::is_directory(ref) && (!mask || fs::is_directory(*mask));
  std::vector<ImagePair> pairs;
  if (by_name) {
    const auto est_files = by_stem(est), ref_files = by_stem(ref);
    const auto only_est = keys_missing_from(est_files, ref_files), only_ref = keys_missing_from(ref_files, est_files);
    if (!only_est.empty() || !only_ref.empty()) {
      std::string msg = "image folders do not match:";
      if (!only_est.empty()) msg += " in " + est.string() + " only: " + join_some(only_est) + ";";
      if (!only_ref.empty()) msg += " in " + ref.string() + " only: " + join_some(only_ref) + ";";
      msg.pop_back();
      throw std::runtime_error(msg);
    }
    std::map<std::string, fs::path> mask_files;
    if (mask) {
      mask_files = by_stem(*mask);
      const auto no_mask = keys_missing_from(ref_files, mask_files);
      if (!no_mask.empty())
        throw std::runtime_error("mask folder " + mask->string() + " has no mask for: " + join_some(no_mask));
    }
    for (const auto& [stem, ref_path] : ref_files) {
      ImagePair p{stem, est_files.at(stem), ref_path, std::nullopt};
      if (mask) p.mask = mask_files.at(stem);
      pairs.push_back(std::move(p));
    }
  } else {
    const auto est_files = list_images(est), ref_files = list_images(ref);
    const auto mask_files = mask ? list_images(*mask) : std::vector<fs::path>{};
    if (est_files.size() != ref_files.size() || (mask && mask_files.size() != ref_files.size()))
      throw std::runtime_error("image lists differ in length (matched by order): " + est.string() + " has " +
                               std::to_string(est_files.size()) + ", " + ref.string() + " has " +
                               std::to_string(ref_files.size()) +
                               (mask ? ", " + mask->string() + " has " + std::to_string(mask_files.size()) : ""));
    for (size_t i = 0; i < est_files.size(); ++i) {
      ImagePair p{est_files[i].filename().string(), est_files[i], ref_files[i], std::nullopt};
      if (mask) p.mask = mask_files[i];
      pairs.push_back(std::move(p));
    }
  }
  if (pairs.empty()) throw std::runtime_error("no images matched between " + est.string() + " and " + ref.string());
  return pairs;
}

ImageSetMetrics evaluate_image_pairs(const std::vector<ImagePair>& pairs,
                                     const std::function<void(size_t, size_t)>& progress) {
  if (pairs.empty()) throw std::invalid_argument("evaluate_image_pairs: no image pairs");
  ImageSetMetrics out;
  double sum_psnr = 0.0, sum_ssim = 0.0;
  for (const ImagePair& pair : pairs) {
    const ColorImage est = io::read_color(pair.est);
    const ColorImage ref = io::read_color(pair.ref);
    std::optional<MaskImage> mask;
    if (pair.mask) mask = io::read_mask(*pair.mask);
    ImageScore score{pair};
    try {
      score.psnr_db = psnr(est, ref, mask ? &*mask : nullptr);
      score.ssim = ssim(est, ref, mask ? &*mask : nullptr);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(pair.est.string() + " vs " + pair.ref.string() +
                               (pair.mask ? " (mask " + pair.mask->string() + ")" : std::string()) + ": " + e.what());
    }
    sum_psnr += score.psnr_db;
    sum_ssim += score.ssim;
    out.images.push_back(std::move(score));
    if (progress) progress(out.images.size(), pairs.size());
  }
  out.masked = pairs.front().mask.has_value();
  out.mean_psnr_db = sum_psnr / double(pairs.size());
  out.mean_ssim = sum_ssim / double(pairs.size());
  return out;
}

}  // namespace rrg::eval
