// SubmitSweep's thresholds on physical results (SubmitSweepRequest.
// thresholds): refused with INVALID_ARGUMENT naming the field when a column
// is unknown or a bound is missing, kept with the sweep, and judged on each
// finished item's statistics (SweepItem.threshold_failures), against a
// live cablesim-server.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

v1::SubmitSweepRequest PendulumSweep() {
  v1::SubmitSweepRequest request;
  request.set_name("thresholds");
  *request.mutable_base() = testing::Pendulum(0.05, 1e-3, 1e-2);
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("gravity.y");
  axis->add_values(0);
  axis->add_values(-9.81);
  return request;
}

TEST(ServerSweepThresholds, RefusedJudgedAndKept) {
  testing::ServerProcess server(testing::FreshDir("server_sweep_thresholds_test"), {"--workers=1"});
  auto stub = server.Stub();
  auto submit = [&](const v1::SubmitSweepRequest& request, v1::Sweep* sweep) {
    grpc::ClientContext context;
    return stub->SubmitSweep(&context, request, sweep);
  };
  {
    v1::SubmitSweepRequest request = PendulumSweep();
    request.add_thresholds()->set_column("tip.y");
    v1::Sweep sweep;
    const grpc::Status s = submit(request, &sweep);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(s.error_message(), StartsWith("thresholds[0]: set max, min or both"));
    request.mutable_thresholds(0)->set_max(1);
    v1::SweepThreshold* unknown = request.add_thresholds();
    unknown->set_column("top.fz");
    unknown->set_min(0);
    const grpc::Status u = submit(request, &sweep);
    EXPECT_EQ(u.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(u.error_message(), StartsWith("thresholds[1].column: no frame column \"top.fz\""));
  }
  // The tip starts at y = 0: without gravity it stays there, with gravity
  // it falls below -1e-6.
  v1::SubmitSweepRequest request = PendulumSweep();
  v1::SweepThreshold* t = request.add_thresholds();
  t->set_column("tip.y");
  t->set_min(-1e-6);
  t->set_max(1e-6);
  v1::Sweep sweep;
  ASSERT_TRUE(submit(request, &sweep).ok());
  {
    grpc::ClientContext context;
    v1::WatchSweepRequest watch;
    watch.set_id(sweep.id());
    auto reader = stub->WatchSweep(&context, watch);
    v1::SweepEvent event;
    while (reader->Read(&event)) {
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  grpc::ClientContext context;
  v1::GetSweepResultsRequest get;
  get.set_id(sweep.id());
  v1::SweepResults results;
  ASSERT_TRUE(stub->GetSweepResults(&context, get, &results).ok());
  ASSERT_EQ(results.sweep().thresholds_size(), 1);
  EXPECT_EQ(results.sweep().thresholds(0).column(), "tip.y");
  ASSERT_EQ(results.items_size(), 2);
  for (const v1::SweepItem& item : results.items()) {
    EXPECT_EQ(item.state(), v1::SUCCEEDED);
    // The items ran with statistics; their tip.y minimum is what is judged.
    double min = 1;
    for (const v1::ColumnStatistics& c : item.summary().statistics().columns())
      if (c.column() == "tip.y") min = c.min();
    if (item.index() == 0) {
      EXPECT_EQ(min, 0);
      EXPECT_EQ(item.threshold_failures_size(), 0);
    } else {
      EXPECT_LT(min, -1e-6);
      ASSERT_EQ(item.threshold_failures_size(), 1);
      EXPECT_THAT(item.threshold_failures(0), StartsWith("tip.y min -"));
      EXPECT_THAT(item.threshold_failures(0), HasSubstr("is below -1e-06"));
    }
  }
}

}  // namespace
}  // namespace cablesim
