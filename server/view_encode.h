#pragma once
// A Session render (SessionView) -> the PNG images of RenderViewResponse: colour passes as 8-bit
// RGB, the reflection mask R as 8-bit grey (0 / 255), depth D_b as 16-bit grey in millimetres
// (0 = no surface; depths beyond 65.535 m are written 0).
#include "core/slam/session.h"
#include "rrg/v1/service.pb.h"

#include <vector>

namespace rrg::server {

// passes empty = PASS_FINAL. Throws std::invalid_argument for an unknown pass.
v1::RenderViewResponse encode_view(const SessionView& view, const std::vector<v1::RenderPass>& passes);

}  // namespace rrg::server
