#pragma once
// Internal to core/io: tiny helpers for the line-oriented text formats (TUM lists, trajectories,
// 7-Scenes poses, Replica traj.txt). Not part of the public API.
#include <charconv>
#include <optional>
#include <string_view>
#include <vector>

namespace rrg::io {

// Splits a line on spaces, tabs, commas and CR (as TUM's associate.py does); no empty fields.
inline std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\n'; };
  while (i < line.size()) {
    while (i < line.size() && is_sep(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_sep(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// The whole token as a double ("1e-3", "-inf", "nan" accepted; trailing junk is not).
inline std::optional<double> parse_double(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

}  // namespace rrg::io
