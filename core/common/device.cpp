#include "core/common/device.h"

#include "core/common/cuda_runtime.h"

#include <stdexcept>

namespace rrg {

std::string Device::to_string() const {
  return is_cpu() ? std::string("cpu") : "cuda:" + std::to_string(index);
}

bool cuda_compiled() {
#ifdef RRG_WITH_CUDA
  return true;
#else
  return false;
#endif
}

int cuda_device_count() {
#ifdef RRG_WITH_CUDA
  static const int count = detail::cuda_runtime_device_count();
  return count;
#else
  return 0;
#endif
}

std::string cuda_device_name(int index) {
  if (index < 0 || index >= cuda_device_count())
    throw std::runtime_error("no CUDA device " + std::to_string(index));
#ifdef RRG_WITH_CUDA
  return detail::cuda_runtime_device_name(index);
#else
  return {};
#endif
}

std::vector<Device> available_devices() {
  std::vector<Device> devices{Device::cpu()};
  for (int i = 0; i < cuda_device_count(); ++i) devices.push_back(Device::cuda(i));
  return devices;
}

Device default_device() { return cuda_device_count() > 0 ? Device::cuda(0) : Device::cpu(); }

void require_device(const Device& device) {
  if (device.is_cpu()) return;
  if (!cuda_compiled())
    throw std::runtime_error("device " + device.to_string() +
                             " requested, but this build has no CUDA back end (rebuild with nvcc "
                             "and -DRRG_CUDA=ON); use --device cpu");
  const int n = cuda_device_count();
  if (n == 0)
    throw std::runtime_error("device " + device.to_string() +
                             " requested, but no usable GPU was found (no device or driver); "
                             "use --device cpu");
  if (device.index < 0 || device.index >= n)
    throw std::runtime_error("device " + device.to_string() + " requested, but only " +
                             std::to_string(n) + " CUDA device(s) exist");
}

Device parse_device(const std::string& text) {
  Device device;
  if (text == "auto") return default_device();
  if (text == "cpu") {
    device = Device::cpu();
  } else if (text == "cuda") {
    device = Device::cuda(0);
  } else if (text.rfind("cuda:", 0) == 0 && text.size() > 5 &&
             text.find_first_not_of("0123456789", 5) == std::string::npos) {
    device = Device::cuda(std::stoi(text.substr(5)));
  } else {
    throw std::invalid_argument("unknown device '" + text + "' (expected cpu, cuda, cuda:N or auto)");
  }
  require_device(device);
  return device;
}

}  // namespace rrg
