// Selecting the n-th smallest value (internal to digitize/): the medians and
// quantiles of profiles, strips and photos.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <iterator>
#include <vector>

namespace impactlab::digitize {

// Rearranges [first, last) as std::nth_element does and returns *nth: the
// medians and quantiles of the digitizer's profiles and strips. Several
// times faster than std::nth_element, whose partition takes a branch on
// every comparison and mispredicts every other one on noisy data: here the
// swaps are unconditional and the comparison only moves the boundary. Each
// round puts the values below a pivot first and those equal to it next, so
// that the many equal values of an 8-bit photo end it early.
template <typename Iterator>
auto SelectNth(Iterator first, Iterator nth, Iterator last) {
  using Value = typename std::iterator_traits<Iterator>::value_type;
  constexpr std::ptrdiff_t kSmall = 4;  // sorted outright
  // A run of bad pivots would make it quadratic: std::nth_element then.
  int rounds = 2 * std::bit_width(static_cast<std::size_t>(last - first));
  while (last - first > kSmall) {
    if (rounds-- == 0) {
      std::nth_element(first, nth, last);
      return *nth;
    }
    const Value a = *first, b = first[(last - first) / 2], c = last[-1];
    const Value pivot = std::max(std::min(a, b), std::min(std::max(a, b), c));
    Iterator below = first;
    for (Iterator i = first; i != last; ++i) {
      const Value v = *i;
      *i = *below;
      *below = v;
      below += v < pivot;
    }
    if (nth < below) {
      last = below;
      continue;
    }
    Iterator equal = below;
    for (Iterator i = below; i != last; ++i) {
      const Value v = *i;
      *i = *equal;
      *equal = v;
      equal += !(pivot < v);
    }
    if (nth < equal) return *nth;
    first = equal;
  }
  std::sort(first, last);
  return *nth;
}

// The median of `values` by SelectNth (the upper middle one of an even count),
// 0 for none; rearranges `values`.
inline double MedianOf(std::vector<float>& values) {
  if (values.empty()) return 0.0;
  return SelectNth(values.begin(), values.begin() + values.size() / 2, values.end());
}

// The median of `values` (the upper middle one of an even count), 0 for none.
// std::nth_element: these vectors are short, and GCC 12 warns, wrongly, on
// SelectNth inlined into a caller that then frees the copy.
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace impactlab::digitize
