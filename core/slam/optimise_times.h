#pragma once
// How a mapping step's optimisation spends its time (MappingStats, MappingSummary, RunTimings).

namespace rrg {

// The optimisation's iterations by part, milliseconds summed over them: passes 2 and 3 forward
// (projection, binning, rasterisation, composite), the losses and their image gradients, the
// backward passes to every Gaussian parameter, the Adam steps.
struct OptimiseTimes {
  double render = 0, loss = 0, backward = 0, adam = 0;
  OptimiseTimes& operator+=(const OptimiseTimes& o) {
    render += o.render, loss += o.loss, backward += o.backward, adam += o.adam;
    return *this;
  }
  OptimiseTimes scaled(double k) const { return {render * k, loss * k, backward * k, adam * k}; }
};

}  // namespace rrg
