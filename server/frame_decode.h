#pragma once
// A wire Frame (rrg.v1.Frame) -> the SessionFrame a Session takes: checks every field against the
// session's camera and decodes the images (core/io/frame_codec.h). Every problem throws
// std::invalid_argument whose message names the field ("depth.encoding: ...", "color: JPEG is
// 640x480, session expects 160x120"); the caller turns it into INVALID_ARGUMENT.
#include "core/common/camera.h"
#include "core/slam/session.h"
#include "rrg/v1/service.pb.h"

#include <cstddef>
#include <vector>

namespace rrg::server {

// The most bytes one encoded image of `raw_bytes` decoded bytes may take on the wire (PNG and
// JPEG of incompressible data are slightly larger than raw; anything far beyond is refused before
// decoding).
size_t max_encoded_bytes(size_t raw_bytes);

struct DecodedFrame {
  SessionFrame frame;
  std::vector<v1::RenderPass> render;  // passes to render after processing
  double decode_ms = 0;
};

DecodedFrame decode_frame(const v1::Frame& f, const Intrinsics& K, float depth_scale);

}  // namespace rrg::server
