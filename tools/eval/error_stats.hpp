#pragma once
// Summary statistics of a list of errors, as evo reports them (std is the population standard
// deviation, median the mean of the two middle values for an even count).

#include <cstddef>
#include <vector>

namespace posed::eval {

/// All fields carry the unit of the errors summarised ([m] or [deg]); all zero when count = 0.
struct ErrorStats {
  /// number of errors summarised [1]
  std::size_t count = 0;
  /// root mean square [unit]
  double rmse = 0.0;
  /// arithmetic mean [unit]
  double mean = 0.0;
  /// median [unit]
  double median = 0.0;
  /// population standard deviation [unit]
  double std = 0.0;
  /// smallest [unit]
  double min = 0.0;
  /// largest [unit]
  double max = 0.0;
};

ErrorStats summarize(const std::vector<double>& errors);

}  // namespace posed::eval
