#include "server/memory_budget.h"

namespace rrg::server {

std::string MemoryBudget::excess(const SessionStatus& st) const {
  const size_t total = st.device_bytes + st.host_bytes;
  if (memory > 0 && total > memory)
    return std::to_string(total) + " bytes (device + host), over the memory budget of " + std::to_string(memory);
  if (device > 0 && st.device_bytes > device)
    return std::to_string(st.device_bytes) + " device bytes, over the device budget of " + std::to_string(device);
  return {};
}

}  // namespace rrg::server
