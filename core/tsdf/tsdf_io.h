#pragma once
// TSDF volume files (docs/tsdf.md "File format"): a versioned little-endian header with magic,
// format version, voxel layout size, params, volume version and block count, a 64-bit FNV-1a
// checksum of the payload, then every block (resident and streamed out) sorted by coordinate.
#include "core/tsdf/tsdf_volume.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>

namespace rrg {

inline constexpr char kTsdfMagic[8] = {'R', 'R', 'G', 'T', 'S', 'D', 'F', '\0'};
inline constexpr uint32_t kTsdfFormatVersion = 2;  // 2: the truncation band (k, σ_n); 1 still loads, with k = 0

// Written atomically (core/io/atomic_file.h): a failure leaves no file behind.
void save_volume(const TsdfVolume& volume, const std::filesystem::path& path);

// Throws std::runtime_error naming the file for a missing file, wrong magic, unsupported version,
// truncation or checksum mismatch. The volume is created on `device`, with every block resident,
// or, given `resident`, only the blocks for which resident(coord) holds: the others are loaded
// streamed out (host memory), and the block pool holds the resident ones alone.
TsdfVolume load_volume(const std::filesystem::path& path, const Device& device,
                       const std::function<bool(const Eigen::Vector3i&)>& resident = {});

// 64-bit FNV-1a.
uint64_t fnv1a64(std::span<const uint8_t> bytes, uint64_t seed = 14695981039346656037ull);

}  // namespace rrg
