// rrg_test_segmenter: a real rrg.v1.Segmenter server process for tests of the remote semantic cue.
// Two deterministic "models":
//   colour keys (default)  a prompt naming a colour (red, green, blue, white, black) gets the mask
//                          of the pixels within 0.2 of that colour (per channel);
//   --labels DIR           a synthetic sequence's label images: a prompt equal to a category name
//                          (DIR/categories.json) gets that category's pixels of labels/<frame_id>.png.
// Listens on 127.0.0.1:--port (0 = a free port) and prints "listening on 127.0.0.1:PORT" once ready.
#include "core/io/synth_layout.h"
#include "rrg/v1/segmenter.grpc.pb.h"

#include <CLI/CLI.hpp>
#include <grpcpp/grpcpp.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>

namespace {

struct Rgb {
  float r, g, b;
};

const std::map<std::string, Rgb>& colour_keys() {
  static const std::map<std::string, Rgb> keys = {{"red", {1, 0, 0}},   {"green", {0, 1, 0}}, {"blue", {0, 0, 1}},
                                                  {"white", {1, 1, 1}}, {"black", {0, 0, 0}}};
  return keys;
}

class TestSegmenter final : public rrg::v1::Segmenter::Service {
 public:
  explicit TestSegmenter(std::string labels_root) : labels_root_(std::move(labels_root)) {
    if (labels_root_.empty()) return;
    std::ifstream in(rrg::io::synth_scene_file(labels_root_, "categories.json"));
    if (!in) throw std::runtime_error("no categories.json in " + labels_root_);
    // The parsed document must outlive the loop: `for (c : parse(in).at(...))` ranges over a member
    // of a temporary destroyed before the first iteration (it served no category at all).
    const nlohmann::json doc = nlohmann::json::parse(in);
    for (const auto& c : doc.at("categories")) categories_[c.at("name").get<std::string>()] = c.at("id").get<uint16_t>();
    if (categories_.empty()) throw std::runtime_error("no categories in " + labels_root_ + "/categories.json");
  }

  grpc::Status Segment(grpc::ServerContext*, const rrg::v1::SegmentRequest* req,
                       rrg::v1::SegmentResponse* resp) override {
    const auto& img = req->image();
    const size_t n = size_t(img.width()) * img.height();
    if (img.encoding() != rrg::v1::Image::RGB8 || img.data().size() != 3 * n || n == 0)
      return {grpc::StatusCode::INVALID_ARGUMENT, "image must be RGB8 with width * height * 3 bytes"};
    if (req->prompts_size() == 0) return {grpc::StatusCode::INVALID_ARGUMENT, "no prompts"};
    rrg::LabelImage labels;
    if (!labels_root_.empty()) {
      try {
        labels = rrg::io::read_synth_labels(labels_root_, size_t(req->frame_id()));
      } catch (const std::exception& e) {
        return {grpc::StatusCode::NOT_FOUND, e.what()};
      }
      if (size_t(labels.width()) != img.width() || size_t(labels.height()) != img.height())
        return {grpc::StatusCode::INVALID_ARGUMENT, "image size differs from the label images"};
    }
    for (const std::string& prompt : req->prompts()) {
      std::string mask(n, '\0');
      size_t inside = 0;
      if (!labels_root_.empty()) {
        const auto it = categories_.find(prompt);
        if (it == categories_.end()) continue;
        for (size_t i = 0; i < n; ++i)
          if (labels[i] == it->second) mask[i] = 1, ++inside;
      } else {
        const auto it = colour_keys().find(prompt);
        if (it == colour_keys().end()) continue;
        const Rgb k = it->second;
        for (size_t i = 0; i < n; ++i) {
          const auto* p = reinterpret_cast<const unsigned char*>(img.data().data()) + 3 * i;
          if (std::abs(p[0] / 255.0f - k.r) < 0.2f && std::abs(p[1] / 255.0f - k.g) < 0.2f &&
              std::abs(p[2] / 255.0f - k.b) < 0.2f)
            mask[i] = 1, ++inside;
        }
      }
      if (inside == 0) continue;
      auto* inst = resp->add_instances();
      inst->set_label(prompt);
      inst->set_score(0.9f);
      inst->set_width(img.width());
      inst->set_height(img.height());
      inst->set_mask(std::move(mask));
    }
    return grpc::Status::OK;
  }

 private:
  std::string labels_root_;
  std::map<std::string, uint16_t> categories_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rrg_test_segmenter - a deterministic rrg.v1.Segmenter server for tests"};
  int port = 0;
  std::string labels;
  app.add_option("--port", port, "port on 127.0.0.1 (0 = a free one)");
  app.add_option("--labels", labels, "serve masks from this synthetic sequence's label images");
  CLI11_PARSE(app, argc, argv);
  try {
    TestSegmenter service(labels);
    grpc::ServerBuilder builder;
    int selected = 0;
    builder.AddListeningPort("127.0.0.1:" + std::to_string(port), grpc::InsecureServerCredentials(), &selected);
    builder.SetMaxReceiveMessageSize(64 << 20);
    builder.RegisterService(&service);
    std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
    if (!server || selected == 0) {
      std::fprintf(stderr, "rrg_test_segmenter: cannot listen on 127.0.0.1:%d\n", port);
      return 1;
    }
    std::printf("listening on 127.0.0.1:%d\n", selected);
    std::fflush(stdout);
    server->Wait();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rrg_test_segmenter: %s\n", e.what());
    return 1;
  }
  return 0;
}
