#ifndef CABLESIM_CONVERT_RUN_PROTO_H_
#define CABLESIM_CONVERT_RUN_PROTO_H_

// The one place where the engine's run results (ModelInfo, Frame,
// RunSummary; engine/run/simulation.h) meet their cablesim.v1 messages
// (proto/cablesim/v1/service.proto), in both directions. A field added to
// an engine struct is one line in each direction here.
//
// A frame travels as a row of doubles in the order of FrameColumns
// (engine/output/frame_columns.h), the CSV columns of `cablesim run --out`.
// Doubles are copied exactly, so a frame read back with FrameReader is
// bit-identical to the engine's.

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "cablesim/v1/service.pb.h"
#include "engine/output/frame_columns.h"
#include "engine/run/simulation.h"

namespace cablesim {

v1::ModelInfo ModelInfoToProto(const ModelInfo& info);
ModelInfo ModelInfoFromProto(const v1::ModelInfo& proto);

v1::RunSummary SummaryToProto(const RunSummary& summary);
// RunSummary::statistics and RunSummary.statistics.
v1::RunStatistics StatisticsToProto(const RunStatistics& statistics);
RunStatistics StatisticsFromProto(const v1::RunStatistics& proto);
RunSummary SummaryFromProto(const v1::RunSummary& proto);

// Appends `frame` as one row to `values`.
void AppendFrameRow(const Frame& frame, google::protobuf::RepeatedField<double>* values);

// The header of a run's frames: `info` and the column names.
void SetFrameHeader(const ModelInfo& info, v1::RunHeader* header);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_RUN_PROTO_H_
