// How much smaller the job stores keep a trajectory (server/result_codec.h):
// every sample scene in scenes/ is run by the engine, its rows encoded as a
// finished job's result is, and this prints per scene the raw bytes (8 per
// value), the stored bytes, the ratio, plain zstd on the rows for
// comparison, and the encode and decode speeds (median of 5), then the
// median ratio. Usage: server_result_codec_bench [SCENE.json...]
// (default: every scene in scenes/).

#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "convert/run_proto.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"
#include "server/result_codec.h"

namespace cablesim {
namespace {

using Clock = std::chrono::steady_clock;

// The rows of a run, as a job keeps them.
class RowsSink : public FrameSink {
 public:
  absl::Status OnStart(const ModelInfo& info) override {
    v1::RunHeader header;
    SetFrameHeader(info, &header);
    row_size_ = header.columns_size();
    return absl::OkStatus();
  }
  absl::Status OnFrame(const Frame& frame) override {
    scratch_.Clear();
    AppendFrameRow(frame, &scratch_);
    values_.insert(values_.end(), scratch_.begin(), scratch_.end());
    return absl::OkStatus();
  }
  const std::vector<double>& values() const { return values_; }
  int row_size() const { return row_size_; }

 private:
  int row_size_ = 0;
  std::vector<double> values_;
  google::protobuf::RepeatedField<double> scratch_;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int Main(int argc, char** argv) {
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) files.push_back(argv[i]);
  if (files.empty()) {
    for (const auto& e : std::filesystem::directory_iterator(CABLESIM_SOURCE_DIR "/scenes"))
      if (e.path().extension() == ".json") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
  }
  std::printf("%-32s %7s %10s %10s %6s %10s %9s %9s\n", "scene", "rows", "raw_B", "stored_B",
              "ratio", "zstd_rows", "enc_MB/s", "dec_MB/s");
  std::vector<double> ratios;
  for (const std::string& file : files) {
    absl::StatusOr<v1::Scene> proto = ReadSceneFile(file);
    absl::StatusOr<Scene> scene =
        proto.ok() ? SceneFromProto(*proto) : absl::StatusOr<Scene>(proto.status());
    if (!scene.ok()) {
      std::fprintf(stderr, "%s: %s\n", file.c_str(), std::string(scene.status().message()).c_str());
      return 1;
    }
    RowsSink sink;
    if (absl::StatusOr<RunSummary> run = RunScene(*scene, &sink); !run.ok()) {
      std::fprintf(stderr, "%s: %s\n", file.c_str(), std::string(run.status().message()).c_str());
      return 1;
    }
    const std::vector<double>& v = sink.values();
    const double raw = 8.0 * static_cast<double>(v.size());
    std::vector<double> enc_s, dec_s;
    EncodedValues encoded;
    for (int rep = 0; rep < 5; ++rep) {
      auto t0 = Clock::now();
      encoded = EncodeValues(v, sink.row_size());
      auto t1 = Clock::now();
      absl::StatusOr<std::vector<double>> back =
          DecodeValues(encoded.blob, encoded.encoding, sink.row_size());
      auto t2 = Clock::now();
      if (!back.ok() || *back != v) {
        std::fprintf(stderr, "%s: the values do not come back\n", file.c_str());
        return 1;
      }
      enc_s.push_back(std::chrono::duration<double>(t1 - t0).count());
      dec_s.push_back(std::chrono::duration<double>(t2 - t1).count());
    }
    std::string plain(ZSTD_compressBound(static_cast<size_t>(raw)), '\0');
    const size_t plain_size =
        ZSTD_compress(plain.data(), plain.size(), v.data(), static_cast<size_t>(raw), 3);
    const double ratio = raw / static_cast<double>(encoded.blob.size());
    ratios.push_back(ratio);
    std::printf("%-32s %7zu %10.0f %10zu %6.2f %10.2f %9.0f %9.0f\n",
                std::filesystem::path(file).filename().c_str(),
                sink.row_size() > 0 ? v.size() / sink.row_size() : 0, raw, encoded.blob.size(),
                ratio, raw / static_cast<double>(plain_size), raw / 1e6 / Median(enc_s),
                raw / 1e6 / Median(dec_s));
  }
  std::printf("median ratio %.2f over %zu scenes\n", Median(ratios), ratios.size());
  return 0;
}

}  // namespace
}  // namespace cablesim

int main(int argc, char** argv) { return cablesim::Main(argc, argv); }
