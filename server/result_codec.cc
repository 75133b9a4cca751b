#include "server/result_codec.h"

#include <zstd.h>

#include <cstring>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

constexpr int kLevel = 3;

// Rows per column when `count` values are rows of `row_size`.
int64_t Columns(size_t count, int64_t row_size) {
  if (row_size <= 0 || count % static_cast<size_t>(row_size) != 0) return 1;
  return row_size;
}

}  // namespace

EncodedValues EncodeValues(const std::vector<double>& values, int64_t row_size) {
  const size_t n = values.size();
  const int64_t cols = Columns(n, row_size);
  const size_t rows = cols > 0 ? n / static_cast<size_t>(cols) : 0;
  // Byte k of value i (in column-major order) goes to plane k, position i.
  std::string planes(8 * n, '\0');
  size_t i = 0;
  for (int64_t c = 0; c < cols; ++c) {
    for (size_t r = 0; r < rows; ++r, ++i) {
      unsigned char bytes[8];
      std::memcpy(bytes, &values[r * static_cast<size_t>(cols) + static_cast<size_t>(c)], 8);
      for (int k = 0; k < 8; ++k) planes[k * n + i] = static_cast<char>(bytes[k]);
    }
  }
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, kLevel);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
  std::string out(ZSTD_compressBound(planes.size()), '\0');
  const size_t size = ZSTD_compress2(cctx, out.data(), out.size(), planes.data(), planes.size());
  ZSTD_freeCCtx(cctx);
  EncodedValues encoded;
  // Only a too-small buffer makes it fail, and compressBound rules that out.
  if (!ZSTD_isError(size) && size < 8 * n) {
    out.resize(size);
    encoded.encoding = kZstdColumns;
    encoded.blob = std::move(out);
  } else {
    encoded.blob.assign(reinterpret_cast<const char*>(values.data()), 8 * n);
  }
  return encoded;
}

absl::StatusOr<std::vector<double>> DecodeValues(absl::string_view blob, int64_t encoding,
                                                 int64_t row_size) {
  if (encoding == kRawValues) {
    if (blob.size() % sizeof(double) != 0) {
      return absl::DataLossError("the stored values are not whole doubles");
    }
    std::vector<double> v(blob.size() / sizeof(double));
    if (!v.empty()) std::memcpy(v.data(), blob.data(), blob.size());
    return v;
  }
  if (encoding != kZstdColumns) {
    return absl::DataLossError(absl::StrCat("unknown encoding ", encoding, " of stored values"));
  }
  const unsigned long long bytes = ZSTD_getFrameContentSize(blob.data(), blob.size());
  if (bytes == ZSTD_CONTENTSIZE_ERROR || bytes == ZSTD_CONTENTSIZE_UNKNOWN ||
      bytes % sizeof(double) != 0 || bytes > (uint64_t{1} << 40)) {
    return absl::DataLossError("the stored values are not a zstd frame of doubles");
  }
  std::string planes(bytes, '\0');
  const size_t got = ZSTD_decompress(planes.data(), planes.size(), blob.data(), blob.size());
  if (ZSTD_isError(got) || got != bytes) {
    return absl::DataLossError(absl::StrCat("the stored values do not decompress: ",
                                            ZSTD_isError(got) ? ZSTD_getErrorName(got) : "short"));
  }
  const size_t n = bytes / sizeof(double);
  const int64_t cols = Columns(n, row_size);
  const size_t rows = n / static_cast<size_t>(cols);
  std::vector<double> values(n);
  size_t i = 0;
  for (int64_t c = 0; c < cols; ++c) {
    for (size_t r = 0; r < rows; ++r, ++i) {
      unsigned char b[8];
      for (int k = 0; k < 8; ++k) b[k] = static_cast<unsigned char>(planes[k * n + i]);
      std::memcpy(&values[r * static_cast<size_t>(cols) + static_cast<size_t>(c)], b, 8);
    }
  }
  return values;
}

}  // namespace cablesim
