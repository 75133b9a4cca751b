#ifndef CABLESIM_CONVERT_RUN_PROTO_H_
#define CABLESIM_CONVERT_RUN_PROTO_H_

// The one place where the engine's run results (ModelInfo, Frame,
// RunSummary; engine/simulation.h) meet their cablesim.v1 messages
// (proto/cablesim/v1/service.proto), in both directions. A field added to
// an engine struct is one line in each direction here.
//
// A frame travels as a row of doubles in the order of FrameColumns, the
// CSV columns of `cablesim run --out`: t, 9 numbers per probe (position
// [m], velocity [m/s], acceleration [m/s^2]), 5 energies [J] and the
// constraint violation. Doubles are copied exactly, so a frame read back
// with FrameFromRow is bit-identical to the engine's.

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "cablesim/v1/service.pb.h"
#include "engine/simulation.h"

namespace cablesim {

v1::ModelInfo ModelInfoToProto(const ModelInfo& info);
ModelInfo ModelInfoFromProto(const v1::ModelInfo& proto);

v1::RunSummary SummaryToProto(const RunSummary& summary);
RunSummary SummaryFromProto(const v1::RunSummary& proto);

// Numbers per probe in a row, and after the probes.
inline constexpr int kValuesPerProbe = 9;
inline constexpr int kTrailingValues = 7;

// The column names of a frame row for these probes.
std::vector<std::string> FrameColumns(const std::vector<std::string>& probe_names);
inline int FrameRowSize(int probes) { return 1 + kValuesPerProbe * probes + kTrailingValues; }

// Appends `frame` as one row to `values`.
void AppendFrameRow(const Frame& frame, google::protobuf::RepeatedField<double>* values);

// Reads back one row of FrameRowSize(probes) numbers into `frame` (its probe
// vector is resized; no allocation once it has the size).
void FrameFromRow(absl::Span<const double> row, int probes, Frame* frame);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_RUN_PROTO_H_
