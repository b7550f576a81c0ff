#pragma once
// Client side of the frame wire format: core images -> an rrg.v1.Frame with the chosen colour and
// depth encodings (core/io/frame_codec.h does the bytes).
#include "core/common/image.h"
#include "core/io/frame_codec.h"
#include "rrg/v1/service.pb.h"

#include <Eigen/Geometry>

#include <optional>

namespace rrg::service {

struct WireEncoding {
  io::ColorEncoding color = io::ColorEncoding::png;     // lossless by default
  io::DepthEncoding depth = io::DepthEncoding::rvl_zstd;
  io::FrameEncodeOptions options;
};

v1::ColorData::Encoding to_proto(io::ColorEncoding e);
v1::DepthData::Encoding to_proto(io::DepthEncoding e);

v1::Frame encode_frame(uint64_t id, double timestamp, const ColorImage& color, const DepthImage& depth,
                       float depth_scale, const WireEncoding& encoding,
                       const std::optional<LabelImage>& labels = std::nullopt,
                       const std::optional<Eigen::Isometry3f>& pose_prior = std::nullopt);

}  // namespace rrg::service
