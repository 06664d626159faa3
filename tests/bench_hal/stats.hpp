// Small order statistics for the benchmark's samples.
#pragma once

#include <cstdint>
#include <vector>

namespace bench {

// Nearest-rank quantile (q in [0, 1]) of a copy of the samples; NaN when empty.
double quantile(std::vector<double> samples, double q);
double median(const std::vector<double>& samples);

// A quantile read from a log-linear histogram: the bucket holding it, as [floor_ns, ceil_ns).
struct BucketRange {
    std::int64_t floor_ns;
    std::int64_t ceil_ns;
};
BucketRange histogram_quantile(const std::vector<std::uint64_t>& counts, double q);

}  // namespace bench
