#include "server/frame_decode.h"

#include "client/lib/proto_convert.h"
#include "core/io/frame_codec.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace rrg::server {

namespace {

io::ColorEncoding color_encoding(v1::ColorData::Encoding e) {
  switch (e) {
    case v1::ColorData::COLOR_RAW_RGB8: return io::ColorEncoding::raw_rgb8;
    case v1::ColorData::COLOR_PNG: return io::ColorEncoding::png;
    case v1::ColorData::COLOR_JPEG: return io::ColorEncoding::jpeg;
    case v1::ColorData::COLOR_ENCODING_UNSPECIFIED:
      throw std::invalid_argument("color.encoding: unspecified (COLOR_RAW_RGB8, COLOR_PNG or COLOR_JPEG)");
    default: break;
  }
  throw std::invalid_argument("color.encoding: unknown value " + std::to_string(int(e)));
}

io::DepthEncoding depth_encoding(v1::DepthData::Encoding e) {
  switch (e) {
    case v1::DepthData::DEPTH_RAW_U16: return io::DepthEncoding::raw_u16;
    case v1::DepthData::DEPTH_PNG16: return io::DepthEncoding::png_u16;
    case v1::DepthData::DEPTH_RVL: return io::DepthEncoding::rvl;
    case v1::DepthData::DEPTH_RVL_ZSTD: return io::DepthEncoding::rvl_zstd;
    case v1::DepthData::DEPTH_RAW_F32: return io::DepthEncoding::raw_f32;
    case v1::DepthData::DEPTH_ENCODING_UNSPECIFIED:
      throw std::invalid_argument(
          "depth.encoding: unspecified (DEPTH_RAW_U16, DEPTH_PNG16, DEPTH_RVL, DEPTH_RVL_ZSTD or DEPTH_RAW_F32)");
    default: break;
  }
  throw std::invalid_argument("depth.encoding: unknown value " + std::to_string(int(e)));
}

io::DepthEncoding label_encoding(v1::LabelData::Encoding e) {
  switch (e) {
    case v1::LabelData::LABEL_RAW_U16: return io::DepthEncoding::raw_u16;
    case v1::LabelData::LABEL_PNG: return io::DepthEncoding::png_u16;
    case v1::LabelData::LABEL_ENCODING_UNSPECIFIED:
      throw std::invalid_argument("labels.encoding: unspecified (LABEL_RAW_U16 or LABEL_PNG)");
    default: break;
  }
  throw std::invalid_argument("labels.encoding: unknown value " + std::to_string(int(e)));
}

void check_size(const std::string& field, size_t bytes, size_t raw_bytes) {
  if (bytes == 0) throw std::invalid_argument(field + ".data: empty");
  const size_t limit = max_encoded_bytes(raw_bytes);
  if (bytes > limit)
    throw std::invalid_argument(field + ".data: " + std::to_string(bytes) + " bytes, more than the " +
                                std::to_string(limit) + " an image of the session's size may take");
}

}  // namespace

size_t max_encoded_bytes(size_t raw_bytes) { return 2 * raw_bytes + 65536; }

DecodedFrame decode_frame(const v1::Frame& f, const Intrinsics& K, float depth_scale) {
  const auto t0 = std::chrono::steady_clock::now();
  DecodedFrame out;
  if (f.id() > uint64_t(std::numeric_limits<int64_t>::max()))
    throw std::invalid_argument("id: " + std::to_string(f.id()) + " is above 2^63 - 1");
  if (!std::isfinite(f.timestamp())) throw std::invalid_argument("timestamp: not finite");
  const size_t pixels = size_t(K.width) * size_t(K.height);
  if (!f.has_color()) throw std::invalid_argument("color: missing");
  if (!f.has_depth()) throw std::invalid_argument("depth: missing");
  const io::ColorEncoding ce = color_encoding(f.color().encoding());
  const io::DepthEncoding de = depth_encoding(f.depth().encoding());
  check_size("color", f.color().data().size(), pixels * 3);
  check_size("depth", f.depth().data().size(), pixels * (de == io::DepthEncoding::raw_f32 ? 4 : 2));

  SessionFrame& s = out.frame;
  s.index = int64_t(f.id());
  s.timestamp = f.timestamp();
  s.color = io::decode_color(io::byte_span(f.color().data()), ce, K.width, K.height);
  s.depth = io::decode_depth(io::byte_span(f.depth().data()), de, K.width, K.height, depth_scale);
  if (f.has_labels()) {
    const io::DepthEncoding le = label_encoding(f.labels().encoding());
    check_size("labels", f.labels().data().size(), pixels * 2);
    s.labels = io::decode_u16_image(io::byte_span(f.labels().data()), le, K.width, K.height, "labels");
  }
  if (f.has_pose_prior()) s.pose = service::from_proto(f.pose_prior(), "pose_prior");
  for (int i = 0; i < f.render_size(); ++i) {
    const auto p = v1::RenderPass(f.render(i));
    if (p < v1::PASS_FINAL || p > v1::PASS_DEPTH)
      throw std::invalid_argument("render[" + std::to_string(i) + "]: unknown pass " + std::to_string(int(p)));
    out.render.push_back(p);
  }
  out.decode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace rrg::server
