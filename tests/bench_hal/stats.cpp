#include "stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "thread.hpp"

namespace bench {

double quantile(std::vector<double> samples, double q) {
    if (samples.empty()) return std::numeric_limits<double>::quiet_NaN();
    auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(samples.size())));
    std::size_t index = rank == 0 ? 0 : std::min(rank - 1, samples.size() - 1);
    std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(index),
                     samples.end());
    return samples[index];
}

double median(const std::vector<double>& samples) {
    return quantile(samples, 0.5);
}

BucketRange histogram_quantile(const std::vector<std::uint64_t>& counts, double q) {
    const std::uint64_t total = std::accumulate(counts.begin(), counts.end(), std::uint64_t{0});
    const auto want = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total)));
    std::uint64_t seen = 0;
    for (std::size_t b = 0; b < counts.size(); ++b) {
        seen += counts[b];
        if (seen >= std::max<std::uint64_t>(want, 1)) {
            const int bucket = static_cast<int>(b);
            const bool last = bucket + 1 >= hal::kHistogramBuckets;
            return {hal::histogram_bucket_floor(bucket),
                    last ? std::numeric_limits<std::int64_t>::max()
                         : hal::histogram_bucket_floor(bucket + 1)};
        }
    }
    return {0, 0};
}

}  // namespace bench
