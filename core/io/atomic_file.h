#pragma once
// Writes that never leave half a file behind: write to "<path>.tmp-<pid>-<n>" in the same folder,
// then rename over the destination. The temporary is removed if the writer throws.
#include <filesystem>
#include <functional>

namespace rrg::io {

// Calls write(tmp_path) and renames tmp_path to path; creates the parent folder if missing.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

}  // namespace rrg::io
