// The rrg.v1.Segmenter client. Compiled against gRPC when the build found it (RRG_WITH_GRPC);
// otherwise make_remote_semantics() says the build has no gRPC.
#include "core/planes/remote_segmenter.h"

#include <stdexcept>

#if RRG_WITH_GRPC
#include "rrg/v1/segmenter.grpc.pb.h"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#endif

namespace rrg {

#if RRG_WITH_GRPC
namespace {

std::shared_ptr<grpc::Channel> channel(const std::string& address) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(256 << 20);  // one byte per pixel per instance
  args.SetMaxSendMessageSize(64 << 20);
  return grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
}

class RemoteSemantics final : public SemanticCue {
 public:
  explicit RemoteSemantics(const RemoteSegmenterOptions& o)
      : options_(o), stub_(v1::Segmenter::NewStub(channel(o.address))) {}
  std::string name() const override { return "remote"; }

  std::vector<SemanticMask> segment(const SemanticFrame& frame) override {
    if (!frame.color) throw std::runtime_error("remote semantics: frame has no colour image");
    const ColorImage& c = *frame.color;
    v1::SegmentRequest req;
    req.set_frame_id(uint64_t(frame.index));
    req.set_box_threshold(options_.box_threshold);
    req.set_text_threshold(options_.text_threshold);
    for (const auto& p : options_.prompts) req.add_prompts(p);
    v1::Image* img = req.mutable_image();
    img->set_width(uint32_t(c.width()));
    img->set_height(uint32_t(c.height()));
    img->set_encoding(v1::Image::RGB8);
    std::string bytes(c.size() * 3, '\0');
    for (size_t i = 0; i < c.size(); ++i)
      for (int ch = 0; ch < 3; ++ch)
        bytes[3 * i + size_t(ch)] = char(uint8_t(std::lround(std::clamp(c[i](ch), 0.0f, 1.0f) * 255.0f)));
    img->set_data(std::move(bytes));

    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() +
                     std::chrono::milliseconds(int64_t(options_.timeout_s * 1000.0)));
    v1::SegmentResponse resp;
    const grpc::Status status = stub_->Segment(&ctx, req, &resp);
    if (!status.ok())
      throw std::runtime_error("remote segmenter at " + options_.address + ": " + status.error_message() +
                               " (gRPC code " + std::to_string(int(status.error_code())) + ")");
    std::vector<SemanticMask> out;
    for (const auto& inst : resp.instances()) {
      if (int(inst.width()) != c.width() || int(inst.height()) != c.height() || inst.mask().size() != c.size())
        throw std::runtime_error("remote segmenter at " + options_.address + ": mask '" + inst.label() +
                                 "' is not " + std::to_string(c.width()) + "x" + std::to_string(c.height()));
      SemanticMask m;
      m.mask = MaskImage(c.width(), c.height(), 0);
      for (size_t i = 0; i < c.size(); ++i) m.mask[i] = inst.mask()[i] ? 1 : 0;
      m.label = inst.label();
      m.score = inst.score();
      m.reflective = label_in(m.label, options_.prompts);
      out.push_back(std::move(m));
    }
    return out;
  }

 private:
  RemoteSegmenterOptions options_;
  std::unique_ptr<v1::Segmenter::Stub> stub_;
};

}  // namespace

bool remote_segmenter_available() { return true; }

std::unique_ptr<SemanticCue> make_remote_semantics(const RemoteSegmenterOptions& options) {
  if (options.address.empty()) throw std::invalid_argument("remote semantics: no segmenter address (host:port)");
  if (options.prompts.empty()) throw std::invalid_argument("remote semantics: empty prompt list");
  return std::make_unique<RemoteSemantics>(options);
}

#else

bool remote_segmenter_available() { return false; }

std::unique_ptr<SemanticCue> make_remote_semantics(const RemoteSegmenterOptions& options) {
  if (options.address.empty()) throw std::invalid_argument("remote semantics: no segmenter address (host:port)");
  throw std::runtime_error("remote semantics: this build has no gRPC (install libgrpc++-dev, protobuf-compiler-grpc "
                           "and reconfigure; see docs/planes.md)");
}

#endif

}  // namespace rrg
