#pragma once
// A 2 x 2 contact sheet of one rendered view for eyeballing a preset: colour | depth (colour
// ramp, near = warm) on top, reflection mask over dimmed colour | plane ids (hashed colours).
#include "core/common/image.h"
#include "core/synth/renderer.h"

namespace rrg::synth {

ColorImage contact_sheet(const RenderOutput& view);

}  // namespace rrg::synth
