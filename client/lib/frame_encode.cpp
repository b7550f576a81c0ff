#include "client/lib/frame_encode.h"

#include "client/lib/proto_convert.h"

namespace rrg::service {

v1::ColorData::Encoding to_proto(io::ColorEncoding e) {
  switch (e) {
    case io::ColorEncoding::raw_rgb8: return v1::ColorData::COLOR_RAW_RGB8;
    case io::ColorEncoding::png: return v1::ColorData::COLOR_PNG;
    case io::ColorEncoding::jpeg: return v1::ColorData::COLOR_JPEG;
  }
  return v1::ColorData::COLOR_ENCODING_UNSPECIFIED;
}

v1::DepthData::Encoding to_proto(io::DepthEncoding e) {
  switch (e) {
    case io::DepthEncoding::raw_u16: return v1::DepthData::DEPTH_RAW_U16;
    case io::DepthEncoding::png_u16: return v1::DepthData::DEPTH_PNG16;
    case io::DepthEncoding::rvl: return v1::DepthData::DEPTH_RVL;
    case io::DepthEncoding::rvl_zstd: return v1::DepthData::DEPTH_RVL_ZSTD;
    case io::DepthEncoding::raw_f32: return v1::DepthData::DEPTH_RAW_F32;
  }
  return v1::DepthData::DEPTH_ENCODING_UNSPECIFIED;
}

v1::Frame encode_frame(uint64_t id, double timestamp, const ColorImage& color, const DepthImage& depth,
                       float depth_scale, const WireEncoding& enc, const std::optional<LabelImage>& labels,
                       const std::optional<Eigen::Isometry3f>& pose_prior) {
  v1::Frame f;
  f.set_id(id);
  f.set_timestamp(timestamp);
  const auto c = io::encode_color(color, enc.color, enc.options);
  f.mutable_color()->set_encoding(to_proto(enc.color));
  f.mutable_color()->set_data(std::string(c.begin(), c.end()));
  const auto d = io::encode_depth(depth, enc.depth, depth_scale, enc.options);
  f.mutable_depth()->set_encoding(to_proto(enc.depth));
  f.mutable_depth()->set_data(std::string(d.begin(), d.end()));
  if (labels) {
    const auto l = io::encode_u16_image(*labels, io::DepthEncoding::png_u16, enc.options);
    f.mutable_labels()->set_encoding(v1::LabelData::LABEL_PNG);
    f.mutable_labels()->set_data(std::string(l.begin(), l.end()));
  }
  if (pose_prior) *f.mutable_pose_prior() = to_proto(*pose_prior);
  return f;
}

}  // namespace rrg::service
