#include "server/view_encode.h"

#include "core/io/frame_codec.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg::server {

namespace {

std::string to_bytes(const std::vector<uint8_t>& v) { return std::string(v.begin(), v.end()); }

std::string mask_png(const MaskImage& R) {
  cv::Mat m(R.height(), R.width(), CV_8UC1);
  for (int y = 0; y < R.height(); ++y)
    for (int x = 0; x < R.width(); ++x) m.ptr<uint8_t>(y)[x] = R(x, y) ? 255 : 0;
  std::vector<uint8_t> buf;
  if (!cv::imencode(".png", m, buf, {cv::IMWRITE_PNG_COMPRESSION, 1}))
    throw std::runtime_error("render: PNG encoding of the mask failed");
  return to_bytes(buf);
}

std::string depth_png_mm(const DepthImage& D) {
  Image<uint16_t> mm(D.width(), D.height());
  for (size_t i = 0; i < D.size(); ++i) {
    const double v = std::round(double(D[i]) * 1000.0);
    mm[i] = (std::isfinite(v) && v > 0 && v <= 65535.0) ? uint16_t(v) : uint16_t(0);
  }
  return to_bytes(io::encode_u16_image(mm, io::DepthEncoding::png_u16));
}

}  // namespace

v1::RenderViewResponse encode_view(const SessionView& view, const std::vector<v1::RenderPass>& passes_in) {
  std::vector<v1::RenderPass> passes = passes_in;
  if (passes.empty()) passes.push_back(v1::PASS_FINAL);
  v1::RenderViewResponse out;
  for (const v1::RenderPass pass : passes) {
    v1::RenderedImage* img = out.add_images();
    img->set_pass(pass);
    img->set_width(uint32_t(view.C.width()));
    img->set_height(uint32_t(view.C.height()));
    switch (pass) {
      case v1::PASS_FINAL: img->set_png(to_bytes(io::encode_color(view.C, io::ColorEncoding::png))); break;
      case v1::PASS_BASE: img->set_png(to_bytes(io::encode_color(view.C_b, io::ColorEncoding::png))); break;
      case v1::PASS_REFLECTION: img->set_png(to_bytes(io::encode_color(view.RC_r, io::ColorEncoding::png))); break;
      case v1::PASS_MASK: img->set_png(mask_png(view.R)); break;
      case v1::PASS_DEPTH: img->set_png(depth_png_mm(view.depth)); break;
      default: throw std::invalid_argument("passes: unknown render pass " + std::to_string(int(pass)));
    }
  }
  return out;
}

}  // namespace rrg::server
