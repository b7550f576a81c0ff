#pragma once
// The `remote` semantic cue: a client of rrg.v1.Segmenter (proto/rrg/v1/segmenter.proto), a
// segmenter running in another process (e.g. Grounded SAM2 behind a small gRPC server). Each call
// sends the colour image (8-bit RGB) and the text prompts and receives instance masks with labels
// and scores; a mask is reflective when its label is one of the prompts.
#include "core/planes/semantic_cue.h"

#include <memory>
#include <string>
#include <vector>

namespace rrg {

struct RemoteSegmenterOptions {
  std::string address;                                  // "host:port" (insecure channel)
  std::vector<std::string> prompts = default_prompts();   // text prompts
  float box_threshold = 0.35f;                          // GroundingDINO defaults, passed through
  float text_threshold = 0.25f;
  double timeout_s = 30.0;                              // per call deadline
};

// True when this build has the gRPC client (built with gRPC found at configure time).
bool remote_segmenter_available();

// Throws std::runtime_error when the build has no gRPC, std::invalid_argument for an empty
// address or prompt list. Calls throw std::runtime_error with the gRPC status and the address.
std::unique_ptr<SemanticCue> make_remote_semantics(const RemoteSegmenterOptions& options);

}  // namespace rrg
