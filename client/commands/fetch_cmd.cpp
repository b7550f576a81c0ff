// rrg render | mesh | gaussians: fetch a rendered view, the Draco mesh or the Gaussians of a live
// session from the service and write them to files.
#include "client/commands/command.h"

#if RRG_WITH_GRPC
#include "client/commands/service_common.h"
#include "client/lib/proto_convert.h"
#include "core/io/atomic_file.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace rrg::cli {
namespace {

namespace fs = std::filesystem;

void write_bytes(const fs::path& path, const std::string& data) {
  io::write_atomically(path, [&](const fs::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(data.data(), std::streamsize(data.size()));
    if (!f) throw std::runtime_error("cannot write " + path.string());
  });
}

std::vector<double> parse_numbers(const std::string& text, const std::string& flag, size_t count) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      v.push_back(std::stod(item));
    } catch (const std::exception&) {
      throw std::invalid_argument(flag + ": '" + item + "' is not a number");
    }
  }
  if (v.size() != count) throw std::invalid_argument(flag + ": wants " + std::to_string(count) + " comma-separated numbers");
  return v;
}

v1::RenderPass parse_pass(const std::string& s) {
  if (s == "final") return v1::PASS_FINAL;
  if (s == "base") return v1::PASS_BASE;
  if (s == "reflection") return v1::PASS_REFLECTION;
  if (s == "mask") return v1::PASS_MASK;
  if (s == "depth") return v1::PASS_DEPTH;
  throw std::invalid_argument("--passes: unknown pass '" + s + "' (final, base, reflection, mask, depth)");
}

const char* pass_name(v1::RenderPass p) {
  switch (p) {
    case v1::PASS_FINAL: return "final";
    case v1::PASS_BASE: return "base";
    case v1::PASS_REFLECTION: return "reflection";
    case v1::PASS_MASK: return "mask";
    case v1::PASS_DEPTH: return "depth";
    default: return "unknown";
  }
}

}  // namespace

void register_fetch_commands(CLI::App& app) {
  {
    auto* cmd = app.add_subcommand("render", "render a view of a live session (PNG per pass)");
    auto f = std::make_shared<ServiceFlags>();
    auto pose = std::make_shared<std::string>(), out = std::make_shared<std::string>(".");
    auto passes = std::make_shared<std::vector<std::string>>(std::vector<std::string>{"final"});
    auto intr = std::make_shared<std::string>();
    f->add(*cmd, true);
    cmd->add_option("--pose", *pose, "tx,ty,tz,qx,qy,qz,qw (T_wc; default: the session's last pose)");
    cmd->add_option("--intrinsics", *intr, "fx,fy,cx,cy,width,height (default: the session's camera)");
    cmd->add_option("--passes", *passes, "final, base, reflection, mask, depth")->delimiter(',')->capture_default_str();
    cmd->add_option("--out", *out, "output folder (<pass>.png)")->capture_default_str();
    cmd->callback([=] {
      auto client = f->client();
      const auto h = f->handle();
      v1::RenderViewRequest r;
      if (pose->empty()) {
        *r.mutable_pose() = client.get(h).pose();
      } else {
        const auto v = parse_numbers(*pose, "--pose", 7);
        auto* p = r.mutable_pose();
        p->set_tx(v[0]), p->set_ty(v[1]), p->set_tz(v[2]), p->set_qx(v[3]), p->set_qy(v[4]), p->set_qz(v[5]), p->set_qw(v[6]);
      }
      if (!intr->empty()) {
        const auto v = parse_numbers(*intr, "--intrinsics", 6);
        auto* k = r.mutable_intrinsics();
        k->set_fx(float(v[0])), k->set_fy(float(v[1])), k->set_cx(float(v[2])), k->set_cy(float(v[3]));
        k->set_width(uint32_t(v[4])), k->set_height(uint32_t(v[5]));
      }
      for (const auto& p : *passes) r.add_passes(parse_pass(p));
      const auto resp = client.render(h, r);
      for (const auto& img : resp.images()) {
        const fs::path path = fs::path(*out) / (std::string(pass_name(img.pass())) + ".png");
        write_bytes(path, img.png());
        std::printf("%s: %ux%u, %zu bytes (map version %llu)\n", path.c_str(), img.width(), img.height(),
                    img.png().size(), (unsigned long long)resp.map_version());
      }
    });
  }
  {
    auto* cmd = app.add_subcommand("mesh", "fetch a live session's TSDF mesh as Draco (.drc)");
    auto f = std::make_shared<ServiceFlags>();
    auto out = std::make_shared<std::string>();
    auto since = std::make_shared<uint64_t>(0);
    f->add(*cmd, true);
    cmd->add_option("--out", *out, "output .drc file")->required();
    cmd->add_option("--since", *since, "only blocks changed since this map version");
    cmd->callback([=] {
      const auto b = f->client().mesh(f->handle(), *since);
      if (b.data.empty()) throw std::runtime_error("mesh: the session's mesh is empty (map version " +
                                                   std::to_string(b.map_version) + ")");
      write_bytes(*out, b.data);
      std::printf("%s: %llu vertices, %llu triangles, %zu bytes (map version %llu)\n", out->c_str(),
                  (unsigned long long)b.count, (unsigned long long)b.triangles, b.data.size(),
                  (unsigned long long)b.map_version);
    });
  }
  {
    auto* cmd = app.add_subcommand("gaussians", "fetch a live session's Gaussians (.spz SPZ v3 or .ply 3DGS)");
    auto f = std::make_shared<ServiceFlags>();
    auto out = std::make_shared<std::string>();
    auto set = std::make_shared<std::string>("base");
    f->add(*cmd, true);
    cmd->add_option("--out", *out, "output file; .ply = 3DGS PLY, else SPZ")->required();
    cmd->add_option("--set", *set, "base | reflection")->capture_default_str();
    cmd->callback([=] {
      if (*set != "base" && *set != "reflection") throw std::invalid_argument("--set: base or reflection, got " + *set);
      const bool ply = fs::path(*out).extension() == ".ply";
      const auto b = f->client().gaussians(f->handle(), ply ? v1::GetGaussiansRequest::PLY : v1::GetGaussiansRequest::SPZ,
                                           *set == "base" ? v1::GetGaussiansRequest::BASE : v1::GetGaussiansRequest::REFLECTION);
      write_bytes(*out, b.data);
      std::printf("%s: %llu %s Gaussians, %zu bytes (map version %llu)\n", out->c_str(), (unsigned long long)b.count,
                  set->c_str(), b.data.size(), (unsigned long long)b.map_version);
    });
  }
}

}  // namespace rrg::cli
#else
namespace rrg::cli {
void register_fetch_commands(CLI::App& app) {
  for (const char* name : {"render", "mesh", "gaussians"})
    app.add_subcommand(name, "service client (not in this build)")->callback([] {
      throw std::runtime_error("this build has no gRPC (install libgrpc++-dev protobuf-compiler-grpc, rebuild)");
    });
}
}  // namespace rrg::cli
#endif
