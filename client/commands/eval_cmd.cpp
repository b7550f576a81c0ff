// rrg eval ate|images|mesh: the evaluation instruments of core/eval on files (docs/evaluation.md).
// Tables go to stdout; with --json only the JSON document does (progress is then at debug level).
#include "client/commands/command.h"
#include "core/eval/image_set.h"
#include "core/eval/mesh_metrics.h"
#include "core/eval/observed_mesh_metrics.h"
#include "core/io/dataset.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/ply.h"
#include "core/io/trajectory.h"

#include <nlohmann/json.hpp>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace rrg::cli {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// Two decimals, so a perfect result prints "0.00"; "inf" / "n/a" for the non-finite values.
std::string fixed2(double v) {
  if (std::isnan(v)) return "n/a";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:.2f}", v);
}
// JSON has no inf / NaN: they are written as null (documented in docs/evaluation.md).
json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

void row(const std::string& label, const std::string& value) { std::cout << fmt::format("  {:<30} {}\n", label, value); }

void require_file(const fs::path& path, const std::string& what) {
  if (!fs::is_regular_file(path)) throw std::runtime_error(what + " not found: " + path.string());
}

// Progress at info level for tables, at debug level when stdout must stay pure JSON.
template <class... Args>
void progress(bool json_mode, fmt::format_string<Args...> f, Args&&... args) {
  spdlog::log(json_mode ? spdlog::level::debug : spdlog::level::info, f, std::forward<Args>(args)...);
}

// ---- ate -----------------------------------------------------------------------------------------
struct AteOptions {
  std::string est, ref;
  eval::TrajectoryEvalParams params;
  bool json = false;
};

void run_ate(const AteOptions& o) {
  require_file(o.est, "estimated trajectory");
  require_file(o.ref, "reference trajectory");
  const io::Trajectory est = io::read_tum_trajectory(o.est);
  const io::Trajectory ref = io::read_tum_trajectory(o.ref);
  eval::TrajectoryMetrics m;
  try {
    m = eval::evaluate_trajectory(est, ref, o.params);
  } catch (const std::exception& e) {
    throw std::runtime_error(o.est + " vs " + o.ref + ": " + e.what());
  }
  const eval::AteResult& a = m.ate;
  const eval::RpeResult& r = m.rpe;
  const std::string alignment = a.with_scale ? "sim3" : "rigid";
  if (o.json) {
    json j = {{"est", o.est}, {"ref", o.ref}, {"est_poses", m.est_poses}, {"ref_poses", m.ref_poses},
              {"matched", a.matched}, {"max_dt_s", o.params.max_time_difference},
              {"alignment", alignment}, {"scale", a.alignment.s},
              {"ate_cm", {{"rmse", a.rmse_cm}, {"mean", a.mean_cm}, {"median", a.median_cm}, {"max", a.max_cm},
                          {"rmse_unaligned", a.rmse_unaligned_cm}}},
              {"rpe", {{"delta_s", r.delta_s}, {"pairs", r.pairs}, {"trans_rmse_cm", number_or_null(r.trans_rmse_cm)},
                       {"rot_rmse_deg", number_or_null(r.rot_rmse_deg)}}}};
    std::cout << j.dump(2) << "\n";
    return;
  }
  const std::string per = r.delta_s == 1.0 ? "/s" : fmt::format(" per {:g} s", r.delta_s);
  std::cout << "rrg eval ate: " << o.est << " vs " << o.ref << "\n";
  row("matched poses", fmt::format("{} (est {}, ref {}, max dt {:.3f} s)", a.matched, m.est_poses, m.ref_poses,
                                   o.params.max_time_difference));
  row("alignment", a.with_scale ? fmt::format("Sim(3) Umeyama WITH scale, s = {:.4f} (monocular)", a.alignment.s)
                                : std::string("rigid SE(3) Umeyama, no scale"));
  row("ATE RMSE aligned (cm)", fixed2(a.rmse_cm));
  row("ATE RMSE unaligned (cm)", fixed2(a.rmse_unaligned_cm));
  row("ATE mean aligned (cm)", fixed2(a.mean_cm));
  row("ATE median aligned (cm)", fixed2(a.median_cm));
  row("ATE max aligned (cm)", fixed2(a.max_cm));
  row(fmt::format("RPE pairs (delta {:g} s)", r.delta_s), std::to_string(r.pairs));
  row("RPE trans RMSE (cm" + per + ")", fixed2(r.trans_rmse_cm));
  row("RPE rot RMSE (deg" + per + ")", fixed2(r.rot_rmse_deg));
  if (r.pairs == 0) std::cout << "  (no pose pairs " << r.delta_s << " s apart: the trajectory is too short)\n";
}

// ---- images --------------------------------------------------------------------------------------
struct ImagesOptions {
  std::string est, ref, mask;
  bool json = false;
  bool per_image = false;
};

void run_images(const ImagesOptions& o) {
  const std::optional<fs::path> mask = o.mask.empty() ? std::nullopt : std::optional<fs::path>(o.mask);
  const auto pairs = eval::match_images(o.est, o.ref, mask);
  progress(o.json, "eval images: {} pairs", pairs.size());
  const auto m = eval::evaluate_image_pairs(pairs, [&](size_t done, size_t total) {
    if (done % 10 == 0 || done == total) progress(o.json, "eval images: {}/{}", done, total);
  });
  if (o.json) {
    json j = {{"est", o.est}, {"ref", o.ref}, {"count", m.images.size()}, {"masked", m.masked},
              {"psnr_db", number_or_null(m.mean_psnr_db)}, {"ssim", m.mean_ssim}};
    if (m.masked) j["mask"] = o.mask;
    if (o.per_image) {
      j["images"] = json::array();
      for (const auto& s : m.images)
        j["images"].push_back({{"name", s.pair.name}, {"est", s.pair.est.string()}, {"ref", s.pair.ref.string()},
                               {"psnr_db", number_or_null(s.psnr_db)}, {"ssim", s.ssim}});
    }
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << "rrg eval images: " << o.est << " vs " << o.ref << (m.masked ? " (masked by " + o.mask + ")" : "") << "\n";
  if (o.per_image) {
    std::cout << fmt::format("  {:<30} {:>10} {:>8}\n", "image", "PSNR (dB)", "SSIM");
    for (const auto& s : m.images)
      std::cout << fmt::format("  {:<30} {:>10} {:>8.4f}\n", s.pair.name, fixed2(s.psnr_db), s.ssim);
  }
  row("images", std::to_string(m.images.size()));
  row("mean PSNR (dB)", fixed2(m.mean_psnr_db));
  row("mean SSIM", fmt::format("{:.4f}", m.mean_ssim));
}

// ---- mesh ----------------------------------------------------------------------------------------
struct MeshOptions {
  std::string est, ref;
  std::string observed_by;  // dataset whose frames (ground-truth poses) define the observed surface
  eval::MeshEvalParams params;
  bool json = false;
};

void run_mesh(const MeshOptions& o) {
  require_file(o.est, "estimated mesh");
  require_file(o.ref, "reference mesh");
  const TriangleMesh est = io::read_ply_mesh(o.est);
  const TriangleMesh ref = io::read_ply_mesh(o.ref);
  progress(o.json, "eval mesh: {} / {} vertices, sampling {} points each, nearest neighbours", est.vertices.size(),
           ref.vertices.size(), o.params.samples);
  eval::MeshMetrics m;
  std::optional<eval::ObservedMeshMetrics> seen;  // with --observed-by
  try {
    if (o.observed_by.empty()) {
      m = eval::evaluate_mesh(est, ref, o.params);
    } else {
      const auto dataset = io::open_dataset(o.observed_by);
      if (!dataset->has_ground_truth())
        throw std::runtime_error("--observed-by " + o.observed_by + " has no ground-truth poses");
      seen = eval::evaluate_mesh_observed(est, ref, *dataset, 0, o.params, eval::kObservedDepthTolerance,
                                          [&](size_t done, size_t total) {
                                            if (done % 50 == 0 || done == total)
                                              progress(o.json, "eval mesh: observed surface, frame {}/{}", done, total);
                                          });
      m = seen->whole;
      if (seen->observed) {
        m.completion_cm = seen->observed->completion_cm;
        m.completion_ratio = seen->observed->completion_ratio;
        m.ref_samples = seen->observed->ref_samples;
      }
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(o.est + " vs " + o.ref + ": " + e.what());
  }
  if (seen && !seen->observed) throw std::runtime_error("--observed-by " + o.observed_by + ": no frame observes " + o.ref);
  if (o.json) {
    json j = {{"est", o.est}, {"ref", o.ref}, {"est_samples", m.est_samples}, {"ref_samples", m.ref_samples},
              {"threshold_m", m.threshold_m}, {"accuracy_cm", m.accuracy_cm}, {"completion_cm", m.completion_cm},
              {"accuracy_ratio", m.accuracy_ratio}, {"completion_ratio", m.completion_ratio}};
    if (seen) {
      j["observed_by"] = o.observed_by;
      j["observed_fraction"] = seen->observed_fraction;
      j["completion_whole_mesh_cm"] = seen->whole.completion_cm;
    }
    std::cout << j.dump(2) << "\n";
    return;
  }
  const std::string tau = fmt::format("{:g} cm", 100.0 * m.threshold_m);
  std::cout << "rrg eval mesh: " << o.est << " vs " << o.ref << "\n";
  row("samples (est / ref)", fmt::format("{} / {}", m.est_samples, m.ref_samples));
  row("accuracy (cm)", fixed2(m.accuracy_cm));
  row("completion (cm)", fixed2(m.completion_cm));
  row("accuracy ratio (< " + tau + ", %)", fixed2(100.0 * m.accuracy_ratio));
  row("completion ratio (< " + tau + ", %)", fixed2(100.0 * m.completion_ratio));
  if (seen) {
    row("completion over", fmt::format("the {:.1f}% of the reference observed by {} ({} frames)",
                                       100.0 * seen->observed_fraction, o.observed_by, seen->frames));
    row("completion, all ref. (cm)", fixed2(seen->whole.completion_cm));
  }
}

// A flag value that must be a number > 0 (or >= 0): CLI11's own range check prints DBL_MAX.
CLI::Validator number_above_zero(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        double v = 0.0;
        try {
          size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) return "'" + text + "' is not a number";
        } catch (const std::exception&) {
          return "'" + text + "' is not a number";
        }
        if (!std::isfinite(v) || v < 0.0 || (!allow_zero && v == 0.0))
          return text + " must be " + (allow_zero ? ">= 0" : "> 0");
        return "";
      },
      allow_zero ? "NUMBER >= 0" : "NUMBER > 0");
}

}  // namespace

void register_eval_command(CLI::App& app) {
  auto* eval = app.add_subcommand("eval", "Evaluate trajectories (ATE/RPE), images (PSNR/SSIM), meshes (accuracy/completion)");
  eval->require_subcommand(1);

  auto ate_opts = std::make_shared<AteOptions>();
  auto* ate = eval->add_subcommand("ate", "ATE (rigid alignment, cm) and RPE of TUM trajectories");
  ate->add_option("--est", ate_opts->est, "estimated trajectory (TUM text)")->required();
  ate->add_option("--ref", ate_opts->ref, "reference / ground-truth trajectory (TUM text)")->required();
  ate->add_option("--max-dt", ate_opts->params.max_time_difference, "association window, seconds")
      ->capture_default_str()->check(number_above_zero(true));
  ate->add_option("--rpe-delta", ate_opts->params.rpe_delta, "RPE pose-pair interval, seconds")
      ->capture_default_str()->check(number_above_zero(false));
  ate->add_flag("--with-scale", ate_opts->params.with_scale, "Sim(3) alignment with scale (monocular only)");
  ate->add_flag("--json", ate_opts->json, "print JSON instead of a table");
  ate->callback([ate_opts] { run_ate(*ate_opts); });

  auto img_opts = std::make_shared<ImagesOptions>();
  auto* images = eval->add_subcommand("images", "mean PSNR (peak 1) and SSIM (3DGS) of rendered vs captured images");
  images->add_option("--est", img_opts->est, "rendered images: folder or .txt list")->required();
  images->add_option("--ref", img_opts->ref, "captured images: folder or .txt list")->required();
  images->add_option("--mask", img_opts->mask, "masks (non-zero = scored): folder or .txt list");
  images->add_flag("--json", img_opts->json, "print JSON instead of a table");
  images->add_flag("--per-image", img_opts->per_image, "also list every image's scores");
  images->callback([img_opts] { run_images(*img_opts); });

  auto mesh_opts = std::make_shared<MeshOptions>();
  auto* mesh = eval->add_subcommand("mesh", "accuracy / completion (cm) and ratios of a mesh vs the ground truth");
  mesh->add_option("--est", mesh_opts->est, "reconstructed mesh or point cloud (PLY)")->required();
  mesh->add_option("--ref", mesh_opts->ref, "ground-truth mesh (PLY)")->required();
  mesh->add_option("--samples", mesh_opts->params.samples, "points sampled on each mesh")
      ->capture_default_str()->check(number_above_zero(false));
  mesh->add_option("--threshold", mesh_opts->params.threshold, "ratio threshold, metres")
      ->capture_default_str()->check(number_above_zero(false));
  mesh->add_option("--observed-by", mesh_opts->observed_by,
                   "dataset with ground-truth poses: completion over the reference surface its frames observed "
                   "(depth within 5 cm, facing the camera), as rrg run scores")
      ->check(CLI::ExistingDirectory);
  mesh->add_flag("--json", mesh_opts->json, "print JSON instead of a table");
  mesh->callback([mesh_opts] { run_mesh(*mesh_opts); });
}

}  // namespace rrg::cli
