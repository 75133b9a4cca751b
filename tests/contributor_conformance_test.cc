// Every force contributor (engine/forces/force_contributor.h) against its
// own contract, by central differences, in one place. A new contributor is
// tested by adding one line to kCases below: a label, the contributor's
// name(), and a small scene that uses it in a state where it acts.
//
// Each case builds the scene's model, takes the contributor from it, and
// evaluates it on the full coordinates with the identity map (every
// coordinate its own unknown, s = 1), so the matrices come out whole:
//
//  1. stiffness: K = -dF/dq of the conservative force F (applied load plus
//     conservative part), against the central difference of F;
//  2. energy: F = -dU/dq of the stored energy U (at a load factor of 0.7,
//     so that force and energy must scale alike);
//  3. damping: C = -df_d/dqdot of the dissipative force f_d, against the
//     central difference of f_d in qdot (the contract leaves the
//     q-derivative of f_d out);
//  4. power: the dissipated power equals -f_d . qdot;
//  5. rounding: every force entry's rounding bound covers at least the
//     rounding of the entry itself, eps |f_i| (the floor the model sums);
//  6. static friction (when the contributor has any): its matrix is the
//     derivative of minus its force;
// and a scene without any force feature builds no contributor at all (the
// zero-cost rule).
//
// Tolerances. A central difference with step h has truncation error
// h^2 |f'''| / 6 and rounding error ~ eps |f| / h (each evaluation is
// known to a few eps times the size of its terms). With h = 1e-6 (the
// coordinates are metres or unit directions, the velocities m/s, all of
// order 0.01 to 100) the rounding part is ~ 2e-10 |f| and the truncation
// part ~ 1e-12 |f'''|; every law here is smooth at the chosen states
// (contacts engaged millimetres deep, the buoy piercing the level by a
// metre, the friction's tanh at v / v_s of order one), where |f'''| is at
// most |K| / (0.01 m)^2 for K the matrix scale. So an error bound of 1e-6
// times the scale of the compared quantity (its largest entry, plus the
// energy / 1 m for the energy check) leaves a margin of 100 or more above
// both, while a wrong or missing term (a factor 2, a dropped coupling, a
// sign) shows as an error of order the scale itself. The power is an
// identity up to the rounding of sums of a few dozen products: 1e-12
// times the sum of |f_i qdot_i|.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <ostream>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/constraints/constraint.h"
#include "engine/forces/force_contributor.h"
#include "engine/forces/seabed.h"
#include "engine/forces/wave_load.h"
#include "engine/model/multibody_model.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using Eigen::VectorXd;
using testing::SampleScene;
using testing::SceneFromJson;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kStep = 1e-6;       // central-difference step (see above)
constexpr double kRelative = 1e-6;   // difference against derivative
constexpr double kPowerRel = 1e-12;  // power against -f . qdot
constexpr double kLoadFactor = 0.7;
constexpr double kTime = 12;  // past the waves' ramp

// A 1000 kg block whose four contact points are sunk 2 mm into the bed,
// with damping and friction (tests/seabed_body_test.cc has its physics).
std::string ContactBlock(const char* model, double friction = 0.5) {
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"y": -9.81},
    "bodies": [{"name": "block", "mass": 1000, "inertia": {"x": 100, "y": 120, "z": 110},
                "position": {"y": 0.498},
                "seabed_contact": {"points": [{"x": -0.6, "y": -0.5, "z": -0.4},
                                              {"x": 0.6, "y": -0.5, "z": -0.4},
                                              {"x": -0.6, "y": -0.5, "z": 0.4},
                                              {"x": 0.6, "y": -0.5, "z": 0.4}],
                                   "stiffness": 1e7, "damping": 2e4, "friction": %.17g}}],
    "seabed": {"stiffness": 1e6},
    "solver": {"duration": 1}})",
                         model, friction);
}

// A buoy (d = 2 m, H = 4 m) whose centre is 0.5 m above the still level,
// with drag and added mass, in still water or in waves.
// With `rod_part`, a second part (Body.hydrodynamics_parts): a rod clamped
// across the buoy along its body-frame (y + z) direction.
std::string Buoy(const char* model, bool waves, bool rod_part = false) {
  const char* up = std::string(model) == "PLANAR" ? "y" : "z";
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"%s": -9.81},
    "fluid": {"density": 1025, "water_depth": 50, "current": {"x": 0.3} %s},
    "bodies": [{"name": "buoy", "mass": 4000, "inertia": {"x": 4000, "y": 6000, "z": 6000},
                "position": {"%s": 0.5},
                "hydrodynamics": {"diameter": 2, "height": 4, "drag_coefficient": 1.2,
                                  "heave_drag_coefficient": 0.8, "added_mass": 1,
                                  "heave_added_mass": 0.5} %s}],
    "solver": {"duration": 1}})",
                         model, up,
                         waves ? R"(, "waves": {"regular": [{"height": 2, "period": 8}],
                                                "ramp_time": 5})"
                               : "",
                         up,
                         rod_part ? R"(, "hydrodynamics_parts": [{"diameter": 0.4, "height": 6,
                                         "drag_coefficient": 1.1, "heave_drag_coefficient": 0.5,
                                         "added_mass": 1, "heave_added_mass": 0.2,
                                         "along_axis": true, "axis": {"y": 1, "z": 1}}])"
                                  : "");
}

// How a contributor's matrix relates to its force: the exact derivative,
// or (where its header says so) a symmetric positive semi-definite matrix
// that leaves a non-symmetric term out (the seabed's Coulomb friction:
// forces/seabed.h, "its velocity tangent ... leaves out the rank-one
// term"), which the test checks for symmetry and definiteness instead.
// Or the symmetric part of the derivative, where the header says the
// skew-symmetric part is left out (torques: forces/applied_loads.h).
enum Tangent { kExact, kSymmetricBound, kSymmetricPart };

struct Case {
  const char* label;
  const char* contributor;
  std::function<Scene()> scene;
  Tangent damping = kExact;         // C against -df_d/dqdot
  Tangent static_friction = kExact;  // against -dq_s/dq
  // The velocities' scale [m/s]: of the order of the friction's
  // regularisation speed v_s, where the tanh is curved (far above it the
  // friction force is flat in the velocity and the check weak).
  double speed = 0.1;
  // Whether the conservative force is minus the gradient of the stored
  // energy (not for torques and time-varying loads, whose work is summed
  // per step instead: StepWorkAndEnergyBalanceTheForce checks it).
  bool potential = true;
  Tangent stiffness = kExact;  // K against -dF/dq
  // Whether the velocity-dependent force also holds a convective inertia
  // that dissipates nothing (a reeling winch cable: forces/winch_cables.h),
  // so that the power is not -f . qdot; its damping alone is checked in a
  // case at rest (WinchCablesAtRest).
  bool convective = false;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

// A body with a constant force and torque and time-varying ones at a
// point off its centre.
std::string LoadedBody(const char* model) {
  return absl::StrFormat(R"({
    "model": "%s",
    "bodies": [{"name": "wheel", "mass": 2, "inertia": {"x": 0.25, "y": 0.3, "z": 0.5}}],
    "loads": [{"at": {"body": "wheel", "point": {"x": 0.5, "y": 0.2}},
               "force": {"x": 1, "y": -2}, "torque": %s,
               "varying_force": {"y": {"harmonic": {"amplitude": 3, "frequency": 0.1}}},
               "varying_torque": {"z": {"harmonic": {"amplitude": 2, "frequency": 0.1}}}}],
    "solver": {"duration": 1}})",
                         model,
                         std::string(model) == "PLANAR" ? R"({"z": 1})"
                                                        : R"({"x": 0.3, "y": -0.2, "z": 1})");
}

// A body with linear and angular damping.
std::string DampedBody(const char* model) {
  return absl::StrFormat(R"({
    "model": "%s",
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 0.25, "y": 0.3, "z": 0.5},
                "damping": {"linear": 3, "angular": 0.7}}],
    "solver": {"duration": 1}})",
                         model);
}

// A planar or spatial cable of 20 m hanging from a winch that reels it
// in at 0.5 m/s (14 m left at kTime), with axial and Rayleigh damping on
// the material motion.
std::string ReelingWinch(const char* model) {
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"y": -9.81},
    "cables": [{"name": "rope", "start": {"x": 0, "y": 0}, "direction": {"x": 0.6, "y": 0.8},
                "length": 20, "elements": 6, "density": 7850, "youngs_modulus": 1e9,
                "diameter": 0.02, "bending": "NONE",
                "damping": {"axial_time": 1e-3, "rayleigh_alpha": 0.5},
                "winch": {"speed": {"constant": -0.5}}}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 20}}],
    "solver": {"duration": 1}})",
                         model);
}

// A line that pierces the free surface (the still level y = 0 or z = 0
// 0.625 of the way along its third element, no Gauss point within 0.1 m
// of it): the buoyancy it loses above the level (forces/cable_buoyancy.h).
std::string PiercingLine(const char* model) {
  const char* up = std::string(model) == "PLANAR" ? "y" : "z";
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"%s": -9.81},
    "fluid": {"density": 1025, "free_surface": true},
    "cables": [{"name": "riser", "points": [{"%s": 3}, {"x": 4, "%s": -5}], "elements": 7,
                "density": 7850, "youngs_modulus": 1e9, "diameter": 0.05, "bending": "NONE"}],
    "solver": {"duration": 1}})",
                         model, up, up, up);
}

// One line per contributor (and per variant worth checking).
const Case kCases[] = {
    {"GravityLoadsPendulum", "gravity_loads", [] { return SampleScene("falling-pendulum.json"); }},
    {"GravityLoadsSpatialBody", "gravity_loads", [] { return SceneFromJson(LoadedBody("SPATIAL")); }},
    {"GravityLoadsOnAWinch", "gravity_loads", [] { return SampleScene("crane-winch.json"); }},
    {"WinchCablesAtRest", "winch_cables", [] { return SampleScene("crane-winch.json"); }},
    {"WinchCablesReelingPlanar", "winch_cables", [] { return SceneFromJson(ReelingWinch("PLANAR")); },
     kSymmetricPart, kExact, 0.1, true, kExact, true},
    {"WinchCablesReelingSpatial", "winch_cables",
     [] { return SceneFromJson(ReelingWinch("SPATIAL")); }, kSymmetricPart, kExact, 0.1, true, kExact,
     true},
    {"BodyDampingPlanar", "body_damping", [] { return SceneFromJson(DampedBody("PLANAR")); }},
    {"BodyDampingSpatial", "body_damping", [] { return SceneFromJson(DampedBody("SPATIAL")); }},
    {"AppliedLoadsPlanar", "applied_loads", [] { return SceneFromJson(LoadedBody("PLANAR")); },
     kExact, kExact, 0.1, false, kSymmetricPart},
    {"AppliedLoadsSpatial", "applied_loads", [] { return SceneFromJson(LoadedBody("SPATIAL")); },
     kExact, kExact, 0.1, false, kSymmetricPart},
    {"BodySeabedContactDamperPlanar", "body_seabed_contact",
     [] { return SceneFromJson(ContactBlock("PLANAR", 0)); }},
    {"BodySeabedContactPlanar", "body_seabed_contact",
     [] { return SceneFromJson(ContactBlock("PLANAR")); }, kSymmetricBound, kSymmetricBound},
    {"BodySeabedContactSpatial", "body_seabed_contact",
     [] { return SceneFromJson(ContactBlock("SPATIAL")); }, kSymmetricBound, kSymmetricBound},
    {"BodyFluidPlanar", "body_fluid", [] { return SceneFromJson(Buoy("PLANAR", false)); }},
    {"BodyFluidSpatialInWaves", "body_fluid", [] { return SceneFromJson(Buoy("SPATIAL", true)); }},
    {"BodyFluidPartsSpatialInWaves", "body_fluid",
     [] { return SceneFromJson(Buoy("SPATIAL", true, /*rod_part=*/true)); }},
    {"SlidingJointsZipLine", "sliding_joints", [] { return SampleScene("zip-line.json"); },
     kExact, kExact, 1e-3},
    {"FreeSurfacePlanar", "free_surface", [] { return SceneFromJson(PiercingLine("PLANAR")); }},
    {"FreeSurfaceSpatial", "free_surface", [] { return SceneFromJson(PiercingLine("SPATIAL")); }},
};

// A symmetric bound: m = m^T and no eigenvalue below -1e-12 of its
// largest (rounding of the sums that built it).
void ExpectSymmetricPositiveSemiDefinite(const Eigen::MatrixXd& m) {
  const double scale = m.lpNorm<Eigen::Infinity>();
  EXPECT_LE((m - m.transpose()).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (m + m.transpose()));
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * scale);
}

// A contributor evaluated on full coordinates through the identity map,
// with matrices over all coordinates.
class Harness {
 public:
  Harness(const MultibodyModel& model, const ForceContributor& c)
      : n_(model.coordinates()), dim_(model.dimension()), c_(c), j_(n_), s_(VectorXd::Ones(n_)) {
    std::iota(j_.begin(), j_.end(), 0);
    matrix_.SetPattern(std::vector<int>(n_, 0));
    waves_ = model.wave_load() ? &model.wave_load()->field() : nullptr;
  }
  int n() const { return n_; }

  ForceOutput Output(VectorXd* f, VectorXd* roundoff, bool matrix) {
    f->setZero(n_);
    if (roundoff) roundoff->setZero(n_);
    matrix_.SetZero();
    return ForceOutput{f, roundoff, matrix ? &matrix_ : nullptr, 1.0,
                       CoordinateMap{j_.data(), s_.data(), dim_}};
  }
  ForceState State(const VectorXd& q, const VectorXd* qdot, double load_factor) const {
    return ForceState{&q, qdot, load_factor, kTime, waves_};
  }
  // F = applied load + conservative part; K into `k` when not null.
  VectorXd Conservative(const VectorXd& q, double lf, Eigen::MatrixXd* k = nullptr,
                        VectorXd* roundoff = nullptr) {
    VectorXd f;
    ForceOutput out = Output(&f, nullptr, k != nullptr);
    const ForceState s = State(q, nullptr, lf);
    c_.AddAppliedLoad(s, &out);
    out.roundoff = roundoff;
    if (roundoff) roundoff->setZero(n_);
    c_.AddConservative(s, &out);
    if (k) *k = Dense();
    return f;
  }
  VectorXd Dissipative(const VectorXd& q, const VectorXd& qdot, Eigen::MatrixXd* c = nullptr,
                       VectorXd* roundoff = nullptr) {
    VectorXd f;
    ForceOutput out = Output(&f, roundoff, c != nullptr);
    c_.AddDissipative(State(q, &qdot, 1.0), &out);
    if (c) *c = Dense();
    return f;
  }
  double Energy(const VectorXd& q, double lf) const { return c_.StoredEnergy(State(q, nullptr, lf)); }
  double Power(const VectorXd& q, const VectorXd& qdot) const {
    double p = 0;
    c_.AddDissipatedPower(State(q, &qdot, 1.0), &p);
    return p;
  }
  VectorXd StaticFriction(const VectorXd& q, const VectorXd& q0, Eigen::MatrixXd* m = nullptr) {
    VectorXd f;
    ForceOutput out = Output(&f, nullptr, m != nullptr);
    c_.AddStaticFriction(q, q0, &out);
    if (m) *m = Dense();
    return f;
  }

 private:
  Eigen::MatrixXd Dense() const {
    Eigen::MatrixXd m(n_, n_);
    for (int i = 0; i < n_; ++i)
      for (int k = 0; k < n_; ++k) m(i, k) = matrix_.values()[matrix_.Slot(i, k)];
    return m;
  }
  int n_, dim_;
  const ForceContributor& c_;
  std::vector<int> j_;
  VectorXd s_;
  SkylineLdlt matrix_;
  const WaveField* waves_ = nullptr;
};

// The matrix `m` against minus the central difference of `eval` along each
// coordinate; returns the largest error over the scale.
double DerivativeError(const std::function<VectorXd(const VectorXd&)>& eval, const VectorXd& x,
                       const Eigen::MatrixXd& m, double scale, double step = kStep) {
  double worst = 0;
  for (int i = 0; i < x.size(); ++i) {
    VectorXd xp = x, xm = x;
    xp(i) += step;
    xm(i) -= step;
    const VectorXd column = -(eval(xp) - eval(xm)) / (2 * step);
    worst = std::max(worst, (column - m.col(i)).lpNorm<Eigen::Infinity>() / scale);
  }
  return worst;
}

class ContributorConformanceTest : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    auto model = MultibodyModel::Build(GetParam().scene());
    ASSERT_TRUE(model.ok()) << model.status();
    model_.emplace(std::move(*model));
    model_->SetTime(kTime);
    contributor_ = model_->FindContributor(GetParam().contributor);
    ASSERT_NE(contributor_, nullptr) << GetParam().contributor;
    EXPECT_EQ(contributor_->name(), GetParam().contributor);
    // A state off the scene's layout (every coordinate moved by up to 0.4
    // mm, deterministically) and a velocity of order the case's speed.
    q_.resize(model_->coordinates());
    model_->ToFull(model_->initial_z(), &q_);
    layout_ = q_;
    qdot_.resize(q_.size());
    for (int i = 0; i < q_.size(); ++i) {
      q_(i) += 4e-4 * std::sin(1.7 * i + 0.3);
      qdot_(i) = GetParam().speed * std::cos(2.3 * i + 0.1);
    }
  }
  std::optional<MultibodyModel> model_;
  const ForceContributor* contributor_ = nullptr;
  VectorXd q_, qdot_, layout_;
};

TEST_P(ContributorConformanceTest, StiffnessIsMinusTheForceDerivative) {
  Harness h(*model_, *contributor_);
  Eigen::MatrixXd k;
  const VectorXd f = h.Conservative(q_, kLoadFactor, &k);
  const double scale = std::max(k.lpNorm<Eigen::Infinity>(), f.lpNorm<Eigen::Infinity>());
  if (scale == 0) GTEST_SKIP() << "no conservative force";
  if (GetParam().stiffness == kSymmetricPart) {
    Eigen::MatrixXd fd(q_.size(), q_.size());
    for (int i = 0; i < q_.size(); ++i) {
      VectorXd qp = q_, qm = q_;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd.col(i) = -(h.Conservative(qp, kLoadFactor) - h.Conservative(qm, kLoadFactor)) /
                  (2 * kStep);
    }
    const Eigen::MatrixXd sym = 0.5 * (fd + fd.transpose());
    EXPECT_LE((sym - k).lpNorm<Eigen::Infinity>() / scale, kRelative) << "scale " << scale;
    return;
  }
  const double error = DerivativeError(
      [&](const VectorXd& x) { return h.Conservative(x, kLoadFactor); }, q_, k, scale);
  EXPECT_LE(error, kRelative) << "scale " << scale;
}

// Along a rigid rotation of the whole layout by an angle theta about an
// axis through the origin (every D-vector of q turned: positions, slopes,
// body axes, which stay orthonormal), the work the contributor's force
// does equals the work external agents report (StepWork) minus the rise of
// its stored energy: W(-h, h) - (U(h) - U(-h)) = F(0) . (q(h) - q(-h)) to
// O(h^3) (central). Scale: sum |F_i dq_i| plus |U|.
TEST_P(ContributorConformanceTest, StepWorkAndEnergyBalanceTheForce) {
  Harness h(*model_, *contributor_);
  const int dim = model_->dimension();
  const Eigen::Vector3d axis =
      dim == 2 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(0.3, 0.5, 0.8).normalized();
  auto turned = [&](double theta) {
    const Eigen::Matrix3d r = Eigen::AngleAxisd(theta, axis).toRotationMatrix();
    VectorXd q = layout_;
    for (int i = 0; i + dim <= q.size(); i += dim) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      x.head(dim) = layout_.segment(i, dim);
      q.segment(i, dim) = (r * x).head(dim);
    }
    return q;
  };
  const VectorXd q_minus = turned(-kStep), q_plus = turned(kStep);
  const VectorXd f = h.Conservative(layout_, kLoadFactor);
  double work = 0;
  contributor_->AddStepWork(StepEnds{&q_minus, &q_plus, kTime, kTime, kLoadFactor}, &work);
  const double rise = h.Energy(q_plus, kLoadFactor) - h.Energy(q_minus, kLoadFactor);
  const VectorXd dq = q_plus - q_minus;
  const double scale =
      f.cwiseProduct(dq).cwiseAbs().sum() + std::abs(h.Energy(layout_, kLoadFactor)) * kStep;
  if (scale == 0) GTEST_SKIP() << "no force along the rotation";
  EXPECT_LE(std::abs(work - rise - f.dot(dq)), kRelative * scale) << "scale " << scale;
}

TEST_P(ContributorConformanceTest, ForceIsMinusTheEnergyGradient) {
  if (!GetParam().potential) GTEST_SKIP() << "not a potential's force (its work is per step)";
  Harness h(*model_, *contributor_);
  const VectorXd f = h.Conservative(q_, kLoadFactor);
  const double u = h.Energy(q_, kLoadFactor);
  const double scale = f.lpNorm<Eigen::Infinity>() + std::abs(u) / 1.0;
  if (scale == 0) GTEST_SKIP() << "no stored energy";
  double worst = 0;
  for (int i = 0; i < q_.size(); ++i) {
    VectorXd qp = q_, qm = q_;
    qp(i) += kStep;
    qm(i) -= kStep;
    const double grad = (h.Energy(qp, kLoadFactor) - h.Energy(qm, kLoadFactor)) / (2 * kStep);
    worst = std::max(worst, std::abs(f(i) + grad) / scale);
  }
  EXPECT_LE(worst, kRelative) << "scale " << scale;
}

TEST_P(ContributorConformanceTest, DampingIsMinusTheVelocityDerivative) {
  Harness h(*model_, *contributor_);
  Eigen::MatrixXd c;
  const VectorXd f = h.Dissipative(q_, qdot_, &c);
  const double scale = std::max(c.lpNorm<Eigen::Infinity>(), f.lpNorm<Eigen::Infinity>());
  if (scale == 0) GTEST_SKIP() << "no dissipative force";
  EXPECT_TRUE(contributor_->dissipates());
  if (GetParam().damping == kSymmetricBound) return ExpectSymmetricPositiveSemiDefinite(c);
  if (GetParam().damping == kSymmetricPart) {
    const double step = 1e-5 * GetParam().speed;
    Eigen::MatrixXd fd(q_.size(), q_.size());
    for (int i = 0; i < q_.size(); ++i) {
      VectorXd vp = qdot_, vm = qdot_;
      vp(i) += step;
      vm(i) -= step;
      fd.col(i) = -(h.Dissipative(q_, vp) - h.Dissipative(q_, vm)) / (2 * step);
    }
    const Eigen::MatrixXd sym = 0.5 * (fd + fd.transpose());
    EXPECT_LE((sym - c).lpNorm<Eigen::Infinity>() / scale, kRelative) << "scale " << scale;
    // The part left out is not nothing (else the case checks too little).
    EXPECT_GT((fd - sym).lpNorm<Eigen::Infinity>() / scale, 100 * kRelative);
    return;
  }
  // The step scales with the speed (1e-6 at 0.1 m/s): for a friction law
  // f(v / v_s) with v ~ v_s, the third derivative is ~ f / v_s^3, so the
  // step must be small against v_s too (see the file's comment).
  const double error = DerivativeError(
      [&](const VectorXd& v) { return h.Dissipative(q_, v); }, qdot_, c, scale,
      1e-5 * GetParam().speed);
  EXPECT_LE(error, kRelative) << "scale " << scale;
}

TEST_P(ContributorConformanceTest, DissipatedPowerIsMinusForceTimesVelocity) {
  if (GetParam().convective) GTEST_SKIP() << "a convective inertia rides with the force";
  Harness h(*model_, *contributor_);
  const VectorXd f = h.Dissipative(q_, qdot_);
  const double power = h.Power(q_, qdot_);
  const double bound = kPowerRel * f.cwiseProduct(qdot_).cwiseAbs().sum();
  EXPECT_NEAR(power, -f.dot(qdot_), bound);
  if (!contributor_->dissipates()) {
    EXPECT_EQ(f.lpNorm<Eigen::Infinity>(), 0);
  }
}

TEST_P(ContributorConformanceTest, RoundingBoundCoversEveryForceEntry) {
  Harness h(*model_, *contributor_);
  VectorXd roundoff;
  const VectorXd f = h.Conservative(q_, kLoadFactor, nullptr, &roundoff);
  VectorXd f_only;
  {
    // The applied load's rounding is the model's (eps |sum|); the
    // conservative part's is the contributor's.
    Harness a(*model_, *contributor_);
    VectorXd applied;
    ForceOutput out = a.Output(&applied, nullptr, false);
    contributor_->AddAppliedLoad(a.State(q_, nullptr, kLoadFactor), &out);
    f_only = f - applied;
  }
  for (int i = 0; i < f.size(); ++i) EXPECT_GE(roundoff(i), kEps * std::abs(f_only(i))) << i;
}

TEST_P(ContributorConformanceTest, StaticFrictionMatrixIsMinusItsDerivative) {
  if (!contributor_->has_static_friction()) GTEST_SKIP() << "no static friction";
  Harness h(*model_, *contributor_);
  // Displaced 0.1 mm from where the analysis started (inside the
  // friction's elastic range).
  VectorXd q0 = q_;
  for (int i = 0; i < q0.size(); ++i) q0(i) -= 1e-4 * std::cos(0.9 * i);
  Eigen::MatrixXd m;
  const VectorXd f = h.StaticFriction(q_, q0, &m);
  const double scale = std::max(m.lpNorm<Eigen::Infinity>(), f.lpNorm<Eigen::Infinity>());
  ASSERT_GT(scale, 0);
  if (GetParam().static_friction == kSymmetricBound) return ExpectSymmetricPositiveSemiDefinite(m);
  const double error = DerivativeError(
      [&](const VectorXd& x) { return h.StaticFriction(x, q0); }, q_, m, scale);
  EXPECT_LE(error, kRelative) << "scale " << scale;
}

INSTANTIATE_TEST_SUITE_P(Contributors, ContributorConformanceTest, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.label);
                         });

// A scene without any force feature builds no contributor: nothing is
// evaluated or allocated for features it does not use. A pendulum under
// gravity builds gravity's alone.
TEST(ContributorConformance, ASceneWithoutFeaturesBuildsNoContributor) {
  auto model = MultibodyModel::Build(SampleScene("falling-pendulum.json"));
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->contributors().size(), 1u);
  EXPECT_EQ(model->contributors()[0]->name(), "gravity_loads");
  auto bare = MultibodyModel::Build(SceneFromJson(R"({
    "cables": [{"name": "c", "start": {"x": 0}, "direction": {"x": 1}, "length": 1,
                "elements": 2, "density": 1000, "youngs_modulus": 1e9, "diameter": 0.01}],
    "solver": {"duration": 1}})"));
  ASSERT_TRUE(bare.ok()) << bare.status();
  EXPECT_TRUE(bare->contributors().empty());
}

// Every contributor a sample scene builds has a case above.
TEST(ContributorConformance, EveryContributorOfTheSampleScenesHasACase) {
  const char* samples[] = {"zip-line.json", "mooring-three-line-buoy.json",
                           "mooring-line-in-waves.json", "atwood-machine.json",
                           "crane-winch.json", "damped-cantilever.json", "towed-cable.json"};
  for (const char* file : samples) {
    auto model = MultibodyModel::Build(SampleScene(file));
    ASSERT_TRUE(model.ok()) << file << ": " << model.status();
    for (const auto& c : model->contributors()) {
      bool found = false;
      for (const Case& k : kCases) {
        if (c->name() == k.contributor) found = true;
      }
      EXPECT_TRUE(found) << file << ": " << c->name() << " has no conformance case";
    }
  }
}


// ---- Element terms (ElementTerm, engine/forces/force_contributor.h) ----
//
// Each term of a case's model on one element (4 elements' length 2 m, a
// cubic 2 mm into the seabed at one end and 5 mm at the other, moving at
// 0.1 m/s): the gradient against the central difference of the energy,
// the Hessian against that of the gradient, the damping tangent against
// that of the dissipative force in the rates (or, for Coulomb friction, a
// symmetric positive semi-definite bound, as forces/seabed.h says), the
// power against -f . edot. Tolerances as for the contributors above.

// Where a case's element lies for its potential's checks: sunk into the
// seabed, or pressed into a wheel of radius 0.5 m on the z axis.
enum Place { kInSeabed, kInWheel };

struct ElementCase {
  const char* label;
  const char* term;
  std::function<Scene()> scene;
  Tangent damping = kExact;
  Place place = kInSeabed;
  // The stiffness: exact, or (the sheave's Newton tangent k n n^T,
  // forces/sheave.h) symmetric positive semi-definite.
  Tangent stiffness = kExact;
};

void PrintTo(const ElementCase& c, std::ostream* os) { *os << c.label; }

// `cable_extra`: more of the cable's fields (its own bed's).
std::string SeabedChain(const char* model, const char* bed, const char* cable_extra = "") {
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"y": -9.81},
    "cables": [{"name": "c", "points": [{"x": 0, "y": -20}, {"x": 8, "y": -20}], "density": 7850,
                "youngs_modulus": 2e11, "diameter": 0.05, "elements": 4 %s}],
    "seabed": {"depth": 20, %s},
    "solver": {"duration": 1}})",
                         model, cable_extra, bed);
}

// A cable lying in the fluid (planar: y up; spatial: z up) with
// structural damping, or with drag in a current, or drag and flow inertia
// in waves.
std::string FluidCable(const char* model, const char* extra, const char* cable_extra) {
  const char* up = std::string(model) == "PLANAR" ? "y" : "z";
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"%s": -9.81},
    "fluid": {"density": 1025, "water_depth": 50, "current": {"x": 0.3} %s},
    "cables": [{"name": "c", "points": [{"%s": -20}, {"x": 8, "%s": -19}], "density": 7850,
                "youngs_modulus": 2e11, "diameter": 0.05, "elements": 4 %s}],
    "solver": {"duration": 1}})",
                         model, up, extra, up, up, cable_extra);
}

constexpr const char* kDamping = R"(, "damping": {"axial_time": 2e-3, "bending_time": 5e-3,
    "rayleigh_alpha": 0.3, "rayleigh_beta": 1e-3})";
constexpr const char* kDrag = R"(, "hydrodynamics": {"normal_drag": 1.2,
    "tangential_drag": 0.4, "added_mass": 1})";
constexpr const char* kWaves = R"(, "waves": {"regular": [{"height": 2, "period": 8}],
    "ramp_time": 5})";

// A cable over a wheel (radius 0.5 m at the origin) with damping and
// friction.
std::string OverWheel(const char* model) {
  return absl::StrFormat(R"({
    "model": "%s", "gravity": {"y": -9.81},
    "cables": [{"name": "c", "points": [{"x": -4, "y": 0.6}, {"x": 4, "y": 0.6}], "density": 7850,
                "youngs_modulus": 2e11, "diameter": 0.02, "elements": 4}],
    "sheaves": [{"name": "w", "radius": 0.5, "stiffness": 1e7, "damping": 1e3, "friction": 0.3}],
    "solver": {"duration": 1}})",
                         model);
}

const ElementCase kElementCases[] = {
    {"SheavePlanar", "sheaves", [] { return SceneFromJson(OverWheel("PLANAR")); },
     kSymmetricBound, kInWheel, kSymmetricBound},
    {"SheaveSpatial", "sheaves", [] { return SceneFromJson(OverWheel("SPATIAL")); },
     kSymmetricBound, kInWheel, kSymmetricBound},
    {"CableDampingPlanar", "cable_damping", [] { return SceneFromJson(FluidCable("PLANAR", "", kDamping)); }},
    {"CableDampingSpatial", "cable_damping", [] { return SceneFromJson(FluidCable("SPATIAL", "", kDamping)); }},
    {"CableDragInCurrentPlanar", "cable_fluid_load", [] { return SceneFromJson(FluidCable("PLANAR", "", kDrag)); }},
    {"CableDragInCurrentSpatial", "cable_fluid_load", [] { return SceneFromJson(FluidCable("SPATIAL", "", kDrag)); }},
    {"CableMorisonInWavesPlanar", "cable_fluid_load", [] { return SceneFromJson(FluidCable("PLANAR", kWaves, kDrag)); }},
    {"CableMorisonInWavesSpatial", "cable_fluid_load", [] { return SceneFromJson(FluidCable("SPATIAL", kWaves, kDrag)); }},
    {"CableSeabedDamperPlanar", "cable_seabed",
     [] { return SceneFromJson(SeabedChain("PLANAR", R"("stiffness": 3e5, "damping": 1e4)")); }},
    {"CableSeabedFrictionSpatial", "cable_seabed",
     [] {
       return SceneFromJson(SeabedChain(
           "SPATIAL",
           R"("stiffness": 3e5, "damping": 1e4, "friction_axial": 0.5, "friction_transverse": 1)"));
     },
     kSymmetricBound},
    // A cable on a bed of its own (cables[].seabed_stiffness, seabed_damping).
    {"CableOwnSeabedDamperPlanar", "cable_seabed",
     [] {
       return SceneFromJson(SeabedChain("PLANAR", R"("stiffness": 3e5, "damping": 1e4)",
                                        R"(, "seabed_stiffness": 6e5, "seabed_damping": 2e4)"));
     }},
    {"CableOwnSeabedFrictionSpatial", "cable_seabed",
     [] {
       return SceneFromJson(SeabedChain(
           "SPATIAL",
           R"("stiffness": 3e5, "damping": 1e4, "friction_axial": 0.5, "friction_transverse": 1)",
           R"(, "seabed_stiffness": 6e5, "seabed_damping": 2e4)"));
     },
     kSymmetricBound},
};

class ElementTermConformanceTest : public ::testing::TestWithParam<ElementCase> {
 protected:
  void SetUp() override {
    auto model = MultibodyModel::Build(GetParam().scene());
    ASSERT_TRUE(model.ok()) << model.status();
    model_.emplace(std::move(*model));
    for (const auto& t : model_->element_terms())
      if (t->name() == GetParam().term) term_ = t.get();
    ASSERT_NE(term_, nullptr) << GetParam().term;
  }
  template <int D>
  void Check() {
    using C = ElementCoords<D>;
    using M = ElementMatrix<D>;
    const double length = 2;
    C e, edot;
    for (int i = 0; i < 4 * D; ++i) edot(i) = 0.1 * std::cos(1.9 * i + 0.3);
    // The term's first element, on an element of the given length (the
    // cables' stiffness, as the damping matrix scales with it), at kTime.
    const AncfCableElement<D> element(length, 2e11 * std::numbers::pi * 0.05 * 0.05 / 4,
                                      2e11 * std::numbers::pi * std::pow(0.05, 4) / 64,
                                      BendingModel::kLinear);
    const ElementAt<D> at{element, 0, kTime};
    if (term_->has_potential()) {
      CheckPotential<D>(at, &e);
    } else {
      // Any bent and stretched element (a node's slope 1.05 long).
      for (int i = 0; i < 4 * D; ++i) e(i) = (i % (2 * D) == D ? 1.0 : 0.0) + 0.05 * std::sin(1.3 * i);
      e.template segment<D>(2 * D)(0) += length;
    }
    if (!term_->dissipates()) return;
    ASSERT_TRUE(term_->DissipatesOn(0));
    C f = C::Zero();
    M c = M::Zero();
    const double power = term_->AddElementDissipation(at, e, edot, &f, &c);
    ASSERT_GT(f.template lpNorm<Eigen::Infinity>(), 0) << "no dissipative force";
    EXPECT_NEAR(power, -f.dot(edot), kPowerRel * f.cwiseProduct(edot).cwiseAbs().sum());
    if (GetParam().damping == kSymmetricBound) {
      ExpectSymmetricPositiveSemiDefinite(Eigen::MatrixXd(c));
      return;
    }
    double cerr = 0;
    for (int i = 0; i < 4 * D; ++i) {
      C vp = edot, vm = edot;
      vp(i) += kStep;
      vm(i) -= kStep;
      C fp = C::Zero(), fm = C::Zero();
      term_->AddElementDissipation(at, e, vp, &fp, nullptr);
      term_->AddElementDissipation(at, e, vm, &fm, nullptr);
      cerr = std::max(cerr, (-(fp - fm) / (2 * kStep) - c.col(i)).template lpNorm<Eigen::Infinity>());
    }
    EXPECT_LE(cerr, kRelative * c.template lpNorm<Eigen::Infinity>());
  }
  // The potential's checks, on an element placed where the term acts
  // (Place), which it leaves in *e.
  template <int D>
  void CheckPotential(const ElementAt<D>& at, ElementCoords<D>* e_out) {
    using C = ElementCoords<D>;
    using M = ElementMatrix<D>;
    C& e = *e_out;
    const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
    if (GetParam().place == kInWheel) {
      // Straight across the wheel's top, 5 mm deep at x = 0 (and out of it
      // at the ends), tilted slightly.
      const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
      const Eigen::Vector3d r0 = -x + 0.496 * y, r1 = x + 0.494 * y, t = x - 0.001 * y;
      e << r0.head<D>(), t.head<D>(), r1.head<D>(), t.head<D>();
    } else {
      const Seabed& bed = *model_->seabed();
      // Places the element's nodes below the bed by the given depths (the
      // bed's normal from its height function).
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      for (int d = 0; d < D; ++d)
        n(d) = bed.Height(Eigen::Vector3d::Unit(d)) - bed.Height(Eigen::Vector3d::Zero());
      const double h0 = bed.Height(Eigen::Vector3d::Zero());
      const Eigen::Vector3d r0 = -(h0 + 0.002) * n, r1 = 2 * x - (h0 + 0.005) * n;
      e << r0.head<D>(), (x - 0.0015 * n).head<D>(), r1.head<D>(), (x - 0.0015 * n).head<D>();
    }
    auto energy = [&](const C& ex) {
      double u = 0;
      term_->AddElementEnergy(at, ex, &u);
      return u;
    };
    C g = C::Zero();
    M k = M::Zero();
    const double u = term_->AddElementPotential(at, e, &g, &k, nullptr);
    ASSERT_GT(u, 0) << "the element is not where the term acts";
    EXPECT_NEAR(energy(e), u, 1e-14 * u);
    double gerr = 0, kerr = 0;
    for (int i = 0; i < 4 * D; ++i) {
      C ep = e, em = e;
      ep(i) += kStep;
      em(i) -= kStep;
      gerr = std::max(gerr, std::abs((energy(ep) - energy(em)) / (2 * kStep) - g(i)));
      C gp = C::Zero(), gm = C::Zero();
      term_->AddElementPotential(at, ep, &gp, nullptr, nullptr);
      term_->AddElementPotential(at, em, &gm, nullptr, nullptr);
      kerr = std::max(kerr, ((gp - gm) / (2 * kStep) - k.col(i)).template lpNorm<Eigen::Infinity>());
    }
    EXPECT_LE(gerr, kRelative * (g.template lpNorm<Eigen::Infinity>() + u));
    if (GetParam().stiffness == kSymmetricBound) {
      ExpectSymmetricPositiveSemiDefinite(Eigen::MatrixXd(k));
      EXPECT_GT(k.template lpNorm<Eigen::Infinity>(), 0);
    } else {
      EXPECT_LE(kerr, kRelative * k.template lpNorm<Eigen::Infinity>());
    }
  }
  std::optional<MultibodyModel> model_;
  const ElementTerm* term_ = nullptr;
};

TEST_P(ElementTermConformanceTest, MatchesItsFiniteDifferences) {
  if (model_->dimension() == 2) {
    Check<2>();
  } else {
    Check<3>();
  }
}

INSTANTIATE_TEST_SUITE_P(ElementTerms, ElementTermConformanceTest,
                         ::testing::ValuesIn(kElementCases),
                         [](const ::testing::TestParamInfo<ElementCase>& info) {
                           return std::string(info.param.label);
                         });

// A scene without damping, fluid or seabed builds no element term, and
// every element term a sample scene builds has a case above.
TEST(ElementTermConformance, EveryElementTermOfTheSampleScenesHasACase) {
  auto plain = MultibodyModel::Build(SampleScene("falling-pendulum.json"));
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_TRUE(plain->element_terms().empty());
  const char* samples[] = {"cable-in-current.json", "mooring-line-in-waves.json",
                           "mooring-chain-landing.json", "damped-cantilever.json",
                           "towed-cable.json", "crane-winch.json", "atwood-machine.json",
                           "hook-block.json"};
  for (const char* file : samples) {
    auto model = MultibodyModel::Build(SampleScene(file));
    ASSERT_TRUE(model.ok()) << file << ": " << model.status();
    for (const auto& t : model->element_terms()) {
      bool found = false;
      for (const ElementCase& k : kElementCases) {
        if (t->name() == k.term) found = true;
      }
      EXPECT_TRUE(found) << file << ": " << t->name() << " has no conformance case";
    }
  }
}

// ---- Constraint families (engine/constraints/constraint.h) ----
//
// Each case's model is checked family by family and as a whole, on the
// unknowns z (q = c + S z), at t = 0.7 s (supports moving and turning):
//
//  1. Jacobian: each family's dPhi/dz against the central difference of
//     its residual (step 1e-6; the rows are at most quadratic, so the
//     difference is exact up to rounding eps |q| / h ~ 2e-10 for the
//     metre-sized scenes here: bound 1e-6 of max(1, |J|)).
//  2. Hessian: sum_i lambda_i d^2 Phi_i / dz^2 against the central
//     difference of J(z)^T lambda (same step and bound).
//  3. Time: along z(t) = z0 + v (t - t0) (no acceleration), dPhi/dt = J v
//     + Phi_t (central first difference, step 1e-6 s: truncation h^2
//     Phi''' / 6 ~ 1e-11, rounding ~ 2e-10; bound 1e-6 of max(1, |dPhi/dt|))
//     and d^2 Phi/dt^2 = -gamma (central second difference, step 1e-3 s:
//     truncation h^2 Phi'''' / 12 ~ 1e-5 for the harmonic laws here, of
//     frequency 0.5 Hz on unit lengths, rounding 4 eps |q| / h^2 ~ 1e-9;
//     bound 1e-4 of max(1, |gamma|)).
//  4. Work: a family's step work over [t - h, t + h] at fixed q and
//     multipliers is lambda . Phi_t times 2 h (the work of a rheonomic row
//     is int lambda Phi_t dt), to the same bounds as 3.
// A new family is covered by the scenes below once one of them uses it.

struct ConstraintCase {
  const char* label;
  std::function<Scene()> scene;
};

void PrintTo(const ConstraintCase& c, std::ostream* os) { *os << c.label; }

std::string TurningJson() {
  return R"("rotation": {"ramp": {"slope": 1}, "sum": [{"harmonic": {"amplitude": 0.3,
             "frequency": 0.5}}]}, "rotation_axis": {"x": 0.3, "y": 0.4, "z": 1})";
}

const ConstraintCase kConstraintCases[] = {
    {"TurningBodySpatial",
     [] {
       return SceneFromJson(absl::StrCat(R"({"gravity": {"y": -9.81},
         "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 0.1, "y": 0.15, "z": 0.2},
                     "position": {"x": -0.5}}],
         "joints": [{"type": "FIXED", "a": {"body": "b", "point": {"x": 0.5}}, )",
                                         TurningJson(), R"(}], "solver": {"duration": 1}})"));
     }},
    {"TurningClampedRod",
     [] {
       return SceneFromJson(absl::StrCat(R"({
         "cables": [{"name": "rod", "points": [{"x": 0}, {"x": 1}], "density": 7850,
                     "youngs_modulus": 2e11, "diameter": 0.02, "elements": 4}],
         "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}, )",
                                         TurningJson(), R"(}], "solver": {"duration": 1}})"));
     }},
    {"MovingSupportCraneTrolley", [] { return SampleScene("crane-trolley-hoist.json"); }},
    {"BodyOnCableEndCylinder", [] { return SampleScene("cable-with-end-cylinder.json"); }},
    {"PinnedCylindersPaper", [] { return SampleScene("paper/cylinders-3.json"); }},
};

class ConstraintConformanceTest : public ::testing::TestWithParam<ConstraintCase> {
 protected:
  static constexpr double kT0 = 0.7;
  void SetUp() override {
    auto model = MultibodyModel::Build(GetParam().scene());
    ASSERT_TRUE(model.ok()) << model.status();
    model_.emplace(std::move(*model));
    ASSERT_GT(model_->multipliers(), 0);
    ASSERT_FALSE(model_->constraint_families().empty());
    model_->SetTime(kT0);
    z_ = model_->initial_z();
    v_.resize(z_.size());
    for (int j = 0; j < z_.size(); ++j) {
      z_(j) += 1e-3 * std::sin(1.3 * j + 0.2);
      v_(j) = 0.3 * std::cos(1.1 * j + 0.4);
    }
    lambda_.resize(model_->multipliers());
    for (int i = 0; i < lambda_.size(); ++i) lambda_(i) = 10 * std::sin(0.7 * i + 1);
  }
  VectorXd Full(const VectorXd& z) const {
    VectorXd q(model_->coordinates());
    model_->ToFull(z, &q);
    return q;
  }
  // The family's residual and (dense) Jacobian on z at z.
  VectorXd Residual(const ConstraintFamily& f, const VectorXd& z,
                    Eigen::MatrixXd* jac = nullptr) const {
    VectorXd phi = VectorXd::Zero(model_->multipliers());
    SparseRows pattern = model_->jacobian_pattern();
    std::fill(pattern.value.begin(), pattern.value.end(), 0.0);
    f.Residual(Full(z), model_->Map(), &phi, jac ? &pattern : nullptr);
    if (jac) {
      jac->setZero(phi.size(), z.size());
      for (int r = 0; r < phi.size(); ++r)
        for (int k = pattern.row_start[r]; k < pattern.row_start[r + 1]; ++k)
          (*jac)(r, pattern.col[k]) += pattern.value[k];
    }
    return phi;
  }
  // All families' residual at time t and unknowns z.
  VectorXd Phi(double t, const VectorXd& z) {
    model_->SetTime(t);
    VectorXd phi(model_->multipliers());
    model_->Constraints(Full(z), &phi, nullptr);
    return phi;
  }
  std::optional<MultibodyModel> model_;
  VectorXd z_, v_, lambda_;
};

TEST_P(ConstraintConformanceTest, JacobianIsTheResidualsDerivative) {
  for (const ConstraintFamily* f : model_->constraint_families()) {
    Eigen::MatrixXd jac;
    Residual(*f, z_, &jac);
    const double scale = std::max(1.0, jac.lpNorm<Eigen::Infinity>());
    double worst = 0;
    for (int j = 0; j < z_.size(); ++j) {
      VectorXd zp = z_, zm = z_;
      zp(j) += kStep;
      zm(j) -= kStep;
      const VectorXd column = (Residual(*f, zp) - Residual(*f, zm)) / (2 * kStep);
      worst = std::max(worst, (column - jac.col(j)).lpNorm<Eigen::Infinity>() / scale);
    }
    EXPECT_LE(worst, kRelative) << f->name();
  }
}

TEST_P(ConstraintConformanceTest, HessianIsTheJacobiansDerivative) {
  for (const ConstraintFamily* f : model_->constraint_families()) {
    SkylineLdlt a = model_->mass();
    a.SetZero();
    f->AddHessian(lambda_, 1.0, &a);
    const double scale = std::max(1.0, lambda_.lpNorm<Eigen::Infinity>());
    double worst = 0;
    for (int j = 0; j < z_.size(); ++j) {
      VectorXd zp = z_, zm = z_;
      zp(j) += kStep;
      zm(j) -= kStep;
      Eigen::MatrixXd jp, jm;
      Residual(*f, zp, &jp);
      Residual(*f, zm, &jm);
      const VectorXd column = (jp - jm).transpose() * lambda_ / (2 * kStep);
      for (int i = 0; i < z_.size(); ++i) {
        const int slot = a.Slot(i, j);
        const double h = slot >= 0 ? a.values()[slot] : 0.0;
        worst = std::max(worst, std::abs(column(i) - h) / scale);
      }
    }
    EXPECT_LE(worst, kRelative) << f->name();
  }
}

TEST_P(ConstraintConformanceTest, RateAndGammaAreTheResidualsTimeDerivatives) {
  const VectorXd q = Full(z_);
  VectorXd qdot(model_->coordinates());
  model_->RateToFull(v_, &qdot);
  model_->SetTime(kT0);
  VectorXd rate = VectorXd::Zero(model_->multipliers()), gamma(model_->multipliers());
  for (const ConstraintFamily* f : model_->constraint_families()) f->AddRate(q, &rate);
  model_->ConstraintGamma(q, qdot, &gamma);
  VectorXd phi(model_->multipliers());
  SparseRows jac = model_->jacobian_pattern();
  model_->Constraints(q, &phi, &jac);
  VectorXd jv(phi.size());
  jac.Multiply(v_.data(), jv.data());
  const VectorXd dphi = jv + rate;
  auto path = [&](double dt) { return Phi(kT0 + dt, z_ + dt * v_); };
  const double h1 = kStep, h2 = 1e-3;
  const VectorXd first = (path(h1) - path(-h1)) / (2 * h1);
  const VectorXd second = (path(h2) - 2 * path(0) + path(-h2)) / (h2 * h2);
  EXPECT_LE((first - dphi).lpNorm<Eigen::Infinity>(),
            kRelative * std::max(1.0, dphi.lpNorm<Eigen::Infinity>()));
  EXPECT_LE((second + gamma).lpNorm<Eigen::Infinity>(),
            1e-4 * std::max(1.0, gamma.lpNorm<Eigen::Infinity>()));
}

TEST_P(ConstraintConformanceTest, StepWorkIsTheMultipliersWorkOnTheRate) {
  const VectorXd q = Full(z_);
  for (const ConstraintFamily* f : model_->constraint_families()) {
    model_->SetTime(kT0);
    VectorXd rate = VectorXd::Zero(model_->multipliers());
    f->AddRate(q, &rate);
    double work = 0;
    f->AddStepWork(ConstraintStep{&q, &q, kT0 - kStep, kT0 + kStep, &lambda_, &lambda_}, &work);
    const double expected = lambda_.dot(rate) * 2 * kStep;
    EXPECT_LE(std::abs(work - expected),
              kRelative * std::max(1.0, lambda_.cwiseProduct(rate).cwiseAbs().sum()) * 2 * kStep)
        << f->name();
  }
}

INSTANTIATE_TEST_SUITE_P(Constraints, ConstraintConformanceTest,
                         ::testing::ValuesIn(kConstraintCases),
                         [](const ::testing::TestParamInfo<ConstraintCase>& info) {
                           return std::string(info.param.label);
                         });

}  // namespace
}  // namespace cablesim
