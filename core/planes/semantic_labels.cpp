#include "core/planes/semantic_labels.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <stdexcept>

namespace rrg {

std::string CategoryTable::name(uint16_t id) const {
  const auto it = names.find(id);
  return it != names.end() ? it->second : "category_" + std::to_string(id);
}

CategoryTable read_category_table(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open category table " + file.string());
  CategoryTable table;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& c : j.at("categories")) {
      const int id = c.at("id").get<int>();
      if (id <= 0 || id > 65535) throw std::runtime_error("category id " + std::to_string(id) + " out of range");
      table.names[uint16_t(id)] = c.at("name").get<std::string>();
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("bad category table " + file.string() + ": " + e.what());
  }
  return table;
}

namespace {

class LabelSemantics final : public SemanticCue {
 public:
  LabelSemantics(CategoryTable table, std::vector<std::string> prompts)
      : table_(std::move(table)), prompts_(std::move(prompts)) {
    if (prompts_.empty()) throw std::invalid_argument("labels semantics: empty prompt list");
  }
  std::string name() const override { return "labels"; }
  bool masks_with_every_frame() const override { return true; }

  std::vector<SemanticMask> segment(const SemanticFrame& frame) override {
    if (!frame.labels || frame.labels->empty())
      throw std::runtime_error("labels semantics: frame " + std::to_string(frame.index) + " has no label image");
    const LabelImage& labels = *frame.labels;
    if (frame.color && !frame.color->same_size(labels))
      throw std::runtime_error("labels semantics: label image size differs from the colour image");
    std::map<uint16_t, size_t> index;  // category -> position in out
    std::vector<SemanticMask> out;
    for (size_t i = 0; i < labels.size(); ++i) {
      const uint16_t id = labels[i];
      if (id == 0) continue;
      auto it = index.find(id);
      if (it == index.end()) {
        it = index.emplace(id, out.size()).first;
        SemanticMask m;
        m.mask = MaskImage(labels.width(), labels.height(), 0);
        m.label = table_.name(id);
        m.reflective = label_in(m.label, prompts_);
        out.push_back(std::move(m));
      }
      out[it->second].mask[i] = 1;
    }
    return out;
  }

 private:
  CategoryTable table_;
  std::vector<std::string> prompts_;
};

}  // namespace

std::unique_ptr<SemanticCue> make_label_semantics(CategoryTable table, std::vector<std::string> prompts) {
  return std::make_unique<LabelSemantics>(std::move(table), std::move(prompts));
}

}  // namespace rrg
