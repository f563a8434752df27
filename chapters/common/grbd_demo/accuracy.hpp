#pragma once
// The accuracy of a demo's run (chapter 6, "Accuracy of a step") as the values its chapter quotes.

#include <string>

#include "grbd/io/output.hpp"
#include "grbd_demo/demo.hpp"

namespace grbd::demo {

/// `KEYconverged` (% of the steps), `KEYsweeps` (mean a step), `KEYp99` and `KEYlargest` (the
/// overlaps' 99th percentile and largest [µm]) of `run`, for the tables of chapter 7's experiments.
inline void set_accuracy(Values& values, const std::string& key, const io::RunAccuracy& run) {
  values.set(key + "converged", "%.0f", run.converged_percent());
  values.set(key + "sweeps", "%.0f", run.mean_sweeps());
  values.set(key + "p99", "%.1f", 1e6 * run.p99_overlap());
  values.set(key + "largest", "%.0f", 1e6 * run.max_overlap);
}

}  // namespace grbd::demo
