#ifndef CABLESIM_SERVER_RESULT_CODEC_H_
#define CABLESIM_SERVER_RESULT_CODEC_H_

// How a stored result's values (rows of doubles) are kept in the job
// stores' `vals` column, and the marker (the `encoding` column) that says
// which way a row was written, so that rows written before compression are
// read as they are.
//
// kZstdColumns: the rows are transposed to columns (one column's values
// over time side by side: a probe's coordinate, an energy), the 8 bytes of
// each double split into 8 planes (byte k of every value together: signs,
// exponents and leading mantissa bytes of neighbouring values repeat),
// and the whole compressed by zstd (level 3) with its content checksum.
// On the sample scenes' trajectories this stores 1.7 to 2.3 times fewer
// bytes than the raw doubles (plain zstd on the rows: 1.35 to 1.86);
// bench/result_codec_bench.cc measures it.

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace cablesim {

// Values of the `encoding` column.
inline constexpr int64_t kRawValues = 0;     // row-major doubles, native order
inline constexpr int64_t kZstdColumns = 1;   // as described above

struct EncodedValues {
  int64_t encoding = kRawValues;
  std::string blob;
};

// `values`: rows of `row_size` doubles, row-major (a row_size that is not
// positive or does not divide the count is taken as 1: no transposition).
// kZstdColumns, unless that is no smaller than the raw doubles (a result
// of a few values): then kRawValues.
EncodedValues EncodeValues(const std::vector<double>& values, int64_t row_size);

// The values of a blob written with `encoding` (and the same row_size);
// DataLoss when it does not decode (a damaged or unknown encoding).
absl::StatusOr<std::vector<double>> DecodeValues(absl::string_view blob, int64_t encoding,
                                                 int64_t row_size);

}  // namespace cablesim

#endif  // CABLESIM_SERVER_RESULT_CODEC_H_
