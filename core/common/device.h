#pragma once
// Devices and run-time device selection (DESIGN.md §3). The CPU back end is always present and is
// the oracle; the CUDA back end exists when the library was built with nvcc (cuda_compiled()) and a
// GPU with a working driver is visible (cuda_device_count() > 0).
#include <string>
#include <vector>

namespace rrg {

enum class DeviceType { Cpu, Cuda };

struct Device {
  DeviceType type = DeviceType::Cpu;
  int index = 0;  // CUDA ordinal; 0 for the CPU

  static Device cpu() { return {DeviceType::Cpu, 0}; }
  static Device cuda(int index = 0) { return {DeviceType::Cuda, index}; }
  bool is_cpu() const { return type == DeviceType::Cpu; }
  bool is_cuda() const { return type == DeviceType::Cuda; }
  std::string to_string() const;  // "cpu", "cuda:0"
  bool operator==(const Device&) const = default;
};

bool cuda_compiled();                    // built with the CUDA back end
int cuda_device_count();                 // usable GPUs; 0 without CUDA, GPU or driver
std::string cuda_device_name(int index); // e.g. "NVIDIA H100 80GB HBM3"; throws when absent
std::vector<Device> available_devices(); // CPU first, then every usable CUDA device
Device default_device();                 // cuda:0 when usable, else cpu

// "cpu", "cuda" (= cuda:0), "cuda:N", or "auto" (= default_device()). Throws std::invalid_argument
// for unknown text and std::runtime_error saying why when CUDA is asked for but is not usable
// (not compiled in, no GPU, or N out of range).
Device parse_device(const std::string& text);

// Throws std::runtime_error (as parse_device) unless the device can run work now.
void require_device(const Device& device);

}  // namespace rrg
