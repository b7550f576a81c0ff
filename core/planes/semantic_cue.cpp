#include "core/planes/semantic_cue.h"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace rrg {

const std::vector<std::string>& paper_prompts() {
  static const std::vector<std::string> prompts = {"floor", "table", "vending machine", "closet",
                                                   "wall art", "tv", "whiteboard"};
  return prompts;
}

const std::vector<std::string>& default_prompts() {
  static const std::vector<std::string> prompts = [] {
    std::vector<std::string> p = paper_prompts();
    p.push_back("mirror");
    return p;
  }();
  return prompts;
}

namespace {

std::string normalise(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  std::string out = s.substr(first, last - first + 1);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return out;
}

class NoSemantics final : public SemanticCue {
 public:
  std::string name() const override { return "none"; }
  bool every_plane_is_candidate() const override { return true; }
  std::vector<SemanticMask> segment(const SemanticFrame&) override { return {}; }
};

}  // namespace

bool label_in(const std::string& label, const std::vector<std::string>& prompts) {
  const std::string l = normalise(label);
  return std::any_of(prompts.begin(), prompts.end(), [&](const std::string& p) { return normalise(p) == l; });
}

std::vector<std::string> parse_prompt_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (const std::string n = normalise(item); !n.empty()) out.push_back(n);
  return out;
}

std::unique_ptr<SemanticCue> make_no_semantics() { return std::make_unique<NoSemantics>(); }

}  // namespace rrg
