#include "convert/run_proto.h"

#include "absl/strings/str_cat.h"

namespace cablesim {

v1::ModelInfo ModelInfoToProto(const ModelInfo& info) {
  v1::ModelInfo p;
  p.set_model(info.model);
  p.set_coordinates(info.coordinates);
  p.set_dofs(info.dofs);
  p.set_multipliers(info.multipliers);
  p.set_elements(info.elements);
  p.set_nodes(info.nodes);
  for (const std::string& name : info.probe_names) p.add_probe_names(name);
  for (const std::string& name : info.force_probe_names) p.add_force_probe_names(name);
  for (const std::string& name : info.cable_names) p.add_cable_names(name);
  for (const std::string& name : info.body_names) p.add_body_names(name);
  for (const int n : info.cable_nodes) p.add_cable_nodes(n);
  for (const double s : info.node_s) p.add_node_arc_lengths(s);
  p.set_shape(info.shape);
  p.set_contact(info.contact);
  for (const std::string& name : info.joint_names) p.add_joint_names(name);
  for (const int n : info.joint_reaction_values) p.add_joint_reaction_values(n);
  for (const std::string& name : info.tension_probe_names) p.add_tension_probe_names(name);
  p.set_node_tension(info.node_tension);
  p.set_body_orientation(info.body_orientation);
  for (const std::string& name : info.bending_moment_probe_names)
    p.add_bending_moment_probe_names(name);
  for (const int j : info.release_joints) p.add_release_joints(j);
  return p;
}

ModelInfo ModelInfoFromProto(const v1::ModelInfo& p) {
  ModelInfo info;
  info.model = p.model();
  info.coordinates = p.coordinates();
  info.dofs = p.dofs();
  info.multipliers = p.multipliers();
  info.elements = p.elements();
  info.nodes = p.nodes();
  info.probe_names.assign(p.probe_names().begin(), p.probe_names().end());
  info.force_probe_names.assign(p.force_probe_names().begin(), p.force_probe_names().end());
  info.cable_names.assign(p.cable_names().begin(), p.cable_names().end());
  info.body_names.assign(p.body_names().begin(), p.body_names().end());
  info.cable_nodes.assign(p.cable_nodes().begin(), p.cable_nodes().end());
  info.node_s.assign(p.node_arc_lengths().begin(), p.node_arc_lengths().end());
  info.shape = p.shape();
  info.contact = p.contact();
  info.joint_names.assign(p.joint_names().begin(), p.joint_names().end());
  info.joint_reaction_values.assign(p.joint_reaction_values().begin(),
                                    p.joint_reaction_values().end());
  info.tension_probe_names.assign(p.tension_probe_names().begin(), p.tension_probe_names().end());
  info.node_tension = p.node_tension();
  info.body_orientation = p.body_orientation();
  info.bending_moment_probe_names.assign(p.bending_moment_probe_names().begin(),
                                         p.bending_moment_probe_names().end());
  info.release_joints.assign(p.release_joints().begin(), p.release_joints().end());
  return info;
}

v1::RunStatistics StatisticsToProto(const RunStatistics& s) {
  v1::RunStatistics p;
  for (const ColumnStatistics& c : s.columns) {
    v1::ColumnStatistics* q = p.add_columns();
    q->set_column(c.column);
    q->set_count(c.count);
    q->set_min(c.min);
    q->set_min_t(c.min_t);
    q->set_max(c.max);
    q->set_max_t(c.max_t);
    q->set_mean(c.mean);
    q->set_stddev(c.stddev);
  }
  p.set_sn_slope(s.sn_slope);
  p.set_equivalent_cycles(s.equivalent_cycles);
  for (const RainflowStatistics& r : s.rainflow) {
    v1::RainflowStatistics* q = p.add_rainflow();
    q->set_column(r.column);
    q->set_cycles(r.cycles);
    q->set_half_cycles(r.half_cycles);
    q->set_max_range(r.max_range);
    q->set_damage_equivalent_load(r.damage_equivalent_load);
  }
  return p;
}

RunStatistics StatisticsFromProto(const v1::RunStatistics& p) {
  RunStatistics s;
  for (const v1::ColumnStatistics& q : p.columns()) {
    s.columns.push_back({q.column(), q.count(), q.min(), q.min_t(), q.max(), q.max_t(),
                         q.mean(), q.stddev()});
  }
  s.sn_slope = p.sn_slope();
  s.equivalent_cycles = p.equivalent_cycles();
  for (const v1::RainflowStatistics& q : p.rainflow()) {
    s.rainflow.push_back(
        {q.column(), q.cycles(), q.half_cycles(), q.max_range(), q.damage_equivalent_load()});
  }
  return s;
}

v1::RunSummary SummaryToProto(const RunSummary& s) {
  v1::RunSummary p;
  p.set_status(s.status);
  p.set_error(s.error);
  p.set_failure_time_s(s.failure_time_s);
  p.set_analysis(s.analysis);
  p.set_integrator(s.integrator);
  p.set_linear_solver(s.linear_solver);
  *p.mutable_info() = ModelInfoToProto(s.info);
  p.set_frames(s.frames);
  p.set_steps(s.steps);
  p.set_rejected_steps(s.rejected_steps);
  p.set_newton_iterations(s.newton_iterations);
  p.set_linear_iterations(s.linear_iterations);
  p.set_min_step_s(s.min_step_s);
  p.set_wall_seconds(s.wall_seconds);
  p.set_end_time_s(s.end_time_s);
  p.set_energy_initial(s.energy_initial);
  p.set_energy_final(s.energy_final);
  p.set_energy_dissipated(s.energy_dissipated);
  p.set_energy_damped(s.energy_damped);
  p.set_linear_solves(s.linear_solves);
  p.set_inexact_linear_solves(s.inexact_linear_solves);
  p.set_energy_max_increase(s.energy_max_increase);
  p.set_max_constraint_violation(s.max_constraint_violation);
  p.set_max_newton_residual(s.max_newton_residual);
  p.set_max_residual_floor(s.max_residual_floor);
  p.set_max_linear_residual(s.max_linear_residual);
  for (double f : s.frequencies_hz) p.add_frequencies_hz(f);
  p.set_linear_solver_used(s.linear_solver_used);
  p.set_factorizations(s.factorizations);
  p.set_direct_fallbacks(s.direct_fallbacks);
  p.set_max_step_s(s.max_step_s);
  p.set_adaptive(s.adaptive);
  p.set_rho_infinity(s.rho_infinity);
  p.set_has_error_estimate(s.has_error_estimate);
  p.set_error_estimate_m(s.error_estimate_m);
  p.set_error_estimate_method(s.error_estimate_method);
  p.set_error_estimate_seconds(s.error_estimate_seconds);
  if (s.has_statistics) *p.mutable_statistics() = StatisticsToProto(s.statistics);
  p.set_local_error_estimate_m(s.local_error_estimate_m);
  p.set_accumulated_error_estimate_m(s.accumulated_error_estimate_m);
  p.set_error_tolerance_m(s.error_tolerance_m);
  for (const std::string& w : s.warnings) p.add_warnings(w);
  p.set_integrator_requested(s.integrator_requested);
  p.set_integrator_reason(s.integrator_reason);
  for (const IntegratorSegment& e : s.integrator_segments) {
    v1::IntegratorSegment* g = p.add_integrator_segments();
    g->set_integrator(e.integrator);
    g->set_start_s(e.start_s);
    g->set_steps(e.steps);
    g->set_reason(e.reason);
  }
  for (const JointReleaseEvent& e : s.releases) {
    v1::JointRelease* r = p.add_releases();
    r->set_joint(e.joint);
    r->set_name(e.name);
    r->set_time_s(e.time_s);
    r->set_force_n(e.force_n);
    r->set_cause(e.cause);
  }
  return p;
}

RunSummary SummaryFromProto(const v1::RunSummary& p) {
  RunSummary s;
  s.status = p.status();
  s.error = p.error();
  s.failure_time_s = p.failure_time_s();
  s.analysis = p.analysis();
  s.integrator = p.integrator();
  s.linear_solver = p.linear_solver();
  s.info = ModelInfoFromProto(p.info());
  s.frames = p.frames();
  s.steps = p.steps();
  s.rejected_steps = p.rejected_steps();
  s.newton_iterations = p.newton_iterations();
  s.linear_iterations = p.linear_iterations();
  s.min_step_s = p.min_step_s();
  s.wall_seconds = p.wall_seconds();
  s.end_time_s = p.end_time_s();
  s.energy_initial = p.energy_initial();
  s.energy_final = p.energy_final();
  s.energy_dissipated = p.energy_dissipated();
  s.energy_damped = p.energy_damped();
  s.linear_solves = p.linear_solves();
  s.inexact_linear_solves = p.inexact_linear_solves();
  s.energy_max_increase = p.energy_max_increase();
  s.max_constraint_violation = p.max_constraint_violation();
  s.max_newton_residual = p.max_newton_residual();
  s.max_residual_floor = p.max_residual_floor();
  s.max_linear_residual = p.max_linear_residual();
  s.frequencies_hz.assign(p.frequencies_hz().begin(), p.frequencies_hz().end());
  s.linear_solver_used = p.linear_solver_used();
  s.factorizations = p.factorizations();
  s.direct_fallbacks = p.direct_fallbacks();
  s.max_step_s = p.max_step_s();
  s.adaptive = p.adaptive();
  s.rho_infinity = p.rho_infinity();
  s.has_error_estimate = p.has_error_estimate();
  s.error_estimate_m = p.error_estimate_m();
  s.error_estimate_method = p.error_estimate_method();
  s.error_estimate_seconds = p.error_estimate_seconds();
  s.has_statistics = p.has_statistics();
  if (s.has_statistics) s.statistics = StatisticsFromProto(p.statistics());
  s.local_error_estimate_m = p.local_error_estimate_m();
  s.accumulated_error_estimate_m = p.accumulated_error_estimate_m();
  s.error_tolerance_m = p.error_tolerance_m();
  s.warnings.assign(p.warnings().begin(), p.warnings().end());
  s.integrator_requested = p.integrator_requested();
  s.integrator_reason = p.integrator_reason();
  for (const v1::IntegratorSegment& g : p.integrator_segments())
    s.integrator_segments.push_back({g.integrator(), g.start_s(), g.steps(), g.reason()});
  for (const v1::JointRelease& r : p.releases())
    s.releases.push_back({r.joint(), r.name(), r.time_s(), r.force_n(), r.cause()});
  return s;
}

void AppendFrameRow(const Frame& frame, google::protobuf::RepeatedField<double>* values) {
  ForEachFrameValue(frame, [values](double v) { values->Add(v); });
  ForEachNodeValue(frame, [values](double v) { values->Add(v); });
}

void SetFrameHeader(const ModelInfo& info, v1::RunHeader* header) {
  *header->mutable_info() = ModelInfoToProto(info);
  for (std::string& c : FrameColumns(info)) header->add_columns(std::move(c));
}

}  // namespace cablesim
