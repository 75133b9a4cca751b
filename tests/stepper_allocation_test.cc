// Proves that the steppers (ImplicitEulerStepper, GeneralizedAlphaStepper in
// both variants, with MINRES, GMRES and DIRECT, with and without
// factorization reuse) allocate nothing per step once warmed up.
//
// This file replaces the global operator new/delete family (forwarding to
// malloc/free, aligned_alloc for the aligned forms). On glibc it also
// interposes malloc, calloc, realloc and the aligned C allocators
// (forwarding to glibc's __libc_* entry points), because Eigen's dynamic
// matrices and vectors are allocated with std::malloc, never through
// operator new: counting new alone would miss them. While the counting flag
// is on, every allocation call is counted.
//
// To find an allocation's origin, run with CABLESIM_ALLOC_BACKTRACE=1: each
// counted allocation then prints a backtrace to stderr; resolve its
// `binary(+0xOFFSET)` frames with `addr2line -f -C -e binary 0xOFFSET`
// (build with -g, e.g. RelWithDebInfo, for file and line), or in gdb break
// on PrintBacktrace / CountMalloc while the counting window is open.

#include <execinfo.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <memory>
#include <new>
#include <sstream>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "engine/steppers/implicit_euler_stepper.h"
#include "engine/scene/integrator_traits.h"
#include "engine/steppers/make_stepper.h"
#include "engine/steppers/stepper.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "tests/test_util.h"

namespace {

std::atomic<bool> g_counting{false};
std::atomic<long> g_new_calls{0};     // operator new / new[] (all forms)
std::atomic<long> g_malloc_calls{0};  // malloc family (operator new included)
bool g_backtrace = false;             // set from CABLESIM_ALLOC_BACKTRACE
thread_local bool t_in_hook = false;  // no counting inside the backtrace

[[gnu::noinline]] void PrintBacktrace(const char* what) {
  if (!g_backtrace || t_in_hook) return;
  t_in_hook = true;
  void* frames[64];
  const int n = backtrace(frames, 64);
  static const char kHeader[] = "---- counted allocation: ";
  (void)!write(2, kHeader, sizeof(kHeader) - 1);
  (void)!write(2, what, __builtin_strlen(what));
  (void)!write(2, "\n", 1);
  backtrace_symbols_fd(frames, n, 2);
  t_in_hook = false;
}

[[gnu::noinline]] void CountNew() {
  if (g_counting.load(std::memory_order_relaxed) && !t_in_hook) {
    g_new_calls.fetch_add(1, std::memory_order_relaxed);
    PrintBacktrace("operator new");
  }
}

[[gnu::noinline]] void CountMalloc(const char* what) {
  if (g_counting.load(std::memory_order_relaxed) && !t_in_hook) {
    g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
    PrintBacktrace(what);
  }
}

void* NewOrThrow(std::size_t size) {
  CountNew();
  if (size == 0) size = 1;
  void* p = std::malloc(size);
  if (!p) throw std::bad_alloc();
  return p;
}

void* AlignedNewOrNull(std::size_t size, std::align_val_t align) {
  CountNew();
  const std::size_t a = std::max(static_cast<std::size_t>(align), sizeof(void*));
  // aligned_alloc wants the size to be a multiple of the alignment.
  std::size_t rounded = (std::max<std::size_t>(size, 1) + a - 1) / a * a;
  return std::aligned_alloc(a, rounded);
}

void* AlignedNewOrThrow(std::size_t size, std::align_val_t align) {
  void* p = AlignedNewOrNull(size, align);
  if (!p) throw std::bad_alloc();
  return p;
}

// A window in which allocations are counted.
struct Counts {
  long news = 0;
  long mallocs = 0;
};

class CountingWindow {
 public:
  CountingWindow() {
    new_start_ = g_new_calls.load();
    malloc_start_ = g_malloc_calls.load();
    g_counting.store(true);
  }
  Counts Stop() {
    g_counting.store(false);
    return {g_new_calls.load() - new_start_, g_malloc_calls.load() - malloc_start_};
  }
  ~CountingWindow() { g_counting.store(false); }

 private:
  long new_start_ = 0, malloc_start_ = 0;
};

}  // namespace

// ---- the C allocator (glibc only) ----------------------------------------

#if defined(__GLIBC__)
#define CABLESIM_COUNTS_MALLOC 1
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t size) {
  CountMalloc("malloc");
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  CountMalloc("calloc");
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  CountMalloc("realloc");
  return __libc_realloc(p, size);
}
void* memalign(std::size_t align, std::size_t size) {
  CountMalloc("memalign");
  return __libc_memalign(align, size);
}
void* aligned_alloc(std::size_t align, std::size_t size) {
  CountMalloc("aligned_alloc");
  return __libc_memalign(align, size);
}
int posix_memalign(void** out, std::size_t align, std::size_t size) {
  CountMalloc("posix_memalign");
  if (align < sizeof(void*) || (align & (align - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(align, size);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
void free(void* p) { __libc_free(p); }
}  // extern "C"
#else
#define CABLESIM_COUNTS_MALLOC 0
#endif

// ---- the global operator new / delete family ------------------------------

void* operator new(std::size_t size) { return NewOrThrow(size); }
void* operator new[](std::size_t size) { return NewOrThrow(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  CountNew();
  return std::malloc(size ? size : 1);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  CountNew();
  return std::malloc(size ? size : 1);
}
void* operator new(std::size_t size, std::align_val_t align) {
  return AlignedNewOrThrow(size, align);
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return AlignedNewOrThrow(size, align);
}
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  return AlignedNewOrNull(size, align);
}
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  return AlignedNewOrNull(size, align);
}

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace cablesim {
namespace {

class StepperAllocationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* env = std::getenv("CABLESIM_ALLOC_BACKTRACE");
    g_backtrace = env != nullptr && *env != '\0' && *env != '0';
    if (g_backtrace) {
      // The first backtrace() loads libgcc_s (and allocates): do it now.
      void* frames[4];
      backtrace(frames, 4);
    }
  }
};

// ---- the counter itself counts -------------------------------------------

TEST_F(StepperAllocationTest, CounterSeesOperatorNew) {
  CountingWindow window;
  int* volatile p = new int(7);
  const Counts counts = window.Stop();
  delete p;
  EXPECT_EQ(counts.news, 1);
}

TEST_F(StepperAllocationTest, CounterSeesAlignedAndArrayNew) {
  struct alignas(64) Wide {
    double x[8];
  };
  CountingWindow window;
  Wide* volatile w = new Wide();
  double* volatile a = new double[5];
  const Counts counts = window.Stop();
  delete w;
  delete[] a;
  EXPECT_EQ(counts.news, 2);
}

TEST_F(StepperAllocationTest, CounterSeesEigenHeapVectors) {
  if (!CABLESIM_COUNTS_MALLOC) GTEST_SKIP() << "malloc is counted on glibc only";
  CountingWindow window;
  Eigen::VectorXd v(100);
  double* volatile data = v.data();
  const Counts counts = window.Stop();
  (void)data;
  // Eigen allocates with malloc, not operator new.
  EXPECT_GE(counts.mallocs, 1);
}

// A straight 1 m cable along +x from the origin (E 1e7 Pa, A 1e-4 m^2).
CableSpec UnitCable(std::string name, int elements) {
  CableSpec cable;
  cable.name = std::move(name);
  cable.points = {Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0)};
  cable.length_m = 1;
  cable.elements = elements;
  cable.density_kg_m3 = 1000;
  cable.youngs_modulus_pa = 1e7;
  cable.area_m2 = 1e-4;
  cable.second_moment_m4 = 1e-9;
  return cable;
}

// The counter sees allocations made inside the engine library too (building
// a model fills std::vectors and Eigen vectors).
TEST_F(StepperAllocationTest, CounterSeesEngineAllocations) {
  Scene scene;
  scene.cables.push_back(UnitCable("c", 4));
  CountingWindow window;
  absl::StatusOr<MultibodyModel> model = MultibodyModel::Build(scene);
  const Counts counts = window.Stop();
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_GE(counts.news + counts.mallocs, 1);
  if (CABLESIM_COUNTS_MALLOC) {
    EXPECT_GE(counts.mallocs, 1);
  }
}

// ---- the stepper ----------------------------------------------------------

// Builds the model, warms the stepper up with 5 steps, then counts
// allocations over `steps` steps of size h; all must converge. Every step
// also asks for the local error estimate, and every tenth is taken back
// (Restore) and redone as two half steps, as the adaptive loop does.
void ExpectStepsDoNotAllocate(const Scene& scene, double h, int steps) {
  absl::StatusOr<MultibodyModel> model = MultibodyModel::Build(scene);
  ASSERT_TRUE(model.ok()) << model.status();
  std::unique_ptr<Stepper> owner = MakeStepper(&*model, scene.solver);
  Stepper& stepper = *owner;
  std::string reason;
  ASSERT_TRUE(stepper.Initialize(&reason)) << reason;
  for (int i = 0; i < 5; ++i) {
    const Stepper::StepStats st = stepper.Step(h);
    ASSERT_TRUE(st.converged) << "warm-up step " << i << ": " << st.reason;
  }

  int not_converged = 0, first_failure = -1;
  long newton = 0;
  double error_norms = 0;
  CountingWindow window;
  for (int i = 0; i < steps; ++i) {
    Stepper::StepStats st = stepper.Step(h);
    error_norms += stepper.LocalErrorNorm(h, 1e-4, 1e-3);
    if (i % 10 == 9 && st.converged) {
      stepper.Restore();
      st = stepper.Step(h / 2);
      if (st.converged) st = stepper.Step(h / 2);
    }
    newton += st.newton_iterations;
    if (!st.converged) {
      if (first_failure < 0) first_failure = i;
      ++not_converged;
    }
  }
  const Counts counts = window.Stop();

  EXPECT_EQ(not_converged, 0) << "first failure at counted step " << first_failure;
  if (!TraitsOf(scene.solver.integrator).is_explicit) {
    EXPECT_GT(newton, 0);  // explicit steppers have no Newton iteration
  }
  EXPECT_EQ(counts.news, 0) << "operator new calls in " << steps << " steps "
                            << "(rerun with CABLESIM_ALLOC_BACKTRACE=1 to see where)";
  EXPECT_EQ(counts.mallocs, 0) << "malloc-family calls in " << steps << " steps "
                               << "(rerun with CABLESIM_ALLOC_BACKTRACE=1 to see where)";
  EXPECT_TRUE(stepper.z().allFinite());
  EXPECT_TRUE(std::isfinite(error_norms));
}

// The same with each of the four steppers.
void ExpectEveryStepperDoesNotAllocate(Scene scene, double h, int steps) {
  for (Integrator integrator : {Integrator::kImplicitEuler, Integrator::kGeneralizedAlpha,
                                Integrator::kHht, Integrator::kEnergyMomentum}) {
    SCOPED_TRACE(::testing::Message() << "integrator " << static_cast<int>(integrator));
    scene.solver.Use(integrator);
    ExpectStepsDoNotAllocate(scene, h, steps);
  }
}

// scenes/falling-pendulum.json, built in C++ (12 elements, no multipliers:
// the pin removes the node's position).
Scene FallingPendulum() {
  Scene scene;
  scene.name = "falling-pendulum";
  scene.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);
  CableSpec cable;
  cable.name = "beam";
  cable.points = {Eigen::Vector3d::Zero(), Eigen::Vector3d(1.2, 0, 0)};
  cable.length_m = 1.2;
  cable.elements = 12;
  cable.density_kg_m3 = 5540;
  cable.youngs_modulus_pa = 0.7e6;
  cable.area_m2 = 0.0018;
  cable.second_moment_m4 = 1.215e-8;
  cable.bending = BendingModel::kExact;
  scene.cables.push_back(cable);
  JointSpec pin;
  pin.type = JointType::kPin;
  pin.a.cable = 0;
  pin.a.s_m = 0;
  scene.joints.push_back(pin);
  ProbeSpec tip;
  tip.name = "tip";
  tip.at.cable = 0;
  tip.at.s_m = 1.2;
  scene.probes.push_back(tip);
  scene.solver.analysis = Analysis::kDynamic;
  scene.solver.duration_s = 1.0;
  scene.solver.step_s = 1e-4;
  scene.solver.output_interval_s = 1e-3;
  scene.solver.linear_solver = LinearSolverKind::kMinres;
  scene.solver.Use(Integrator::kImplicitEuler);
  return scene;
}

// A sample scene from scenes/.
Scene SampleScene(const std::string& file) {
  const std::string path = std::string(CABLESIM_SOURCE_DIR) + "/scenes/" + file;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::stringstream json;
  json << in.rdbuf();
  return testing::SceneFromJson(json.str());
}

Scene CableWithEndCylinder(LinearSolverKind linear_solver) {
  Scene scene = SampleScene("cable-with-end-cylinder.json");
  scene.solver.linear_solver = linear_solver;
  scene.solver.Use(Integrator::kImplicitEuler);
  return scene;
}

TEST_F(StepperAllocationTest, FallingPendulumStepsDoNotAllocate) {
  const Scene scene = FallingPendulum();
  ExpectStepsDoNotAllocate(scene, 1e-4, 200);
}

TEST_F(StepperAllocationTest, FallingPendulumGmresStepsDoNotAllocate) {
  Scene scene = FallingPendulum();
  scene.solver.linear_solver = LinearSolverKind::kGmres;
  ExpectStepsDoNotAllocate(scene, 1e-4, 200);
}

TEST_F(StepperAllocationTest, CableWithEndCylinderStepsDoNotAllocate) {
  const Scene scene = CableWithEndCylinder(LinearSolverKind::kMinres);
  ASSERT_FALSE(scene.cables.empty());
  {
    auto model = MultibodyModel::Build(scene);
    ASSERT_TRUE(model.ok()) << model.status();
    ASSERT_GT(model->multipliers(), 0) << "the FIXED cable-body joint should need multipliers";
  }
  ExpectStepsDoNotAllocate(scene, 0.005, 200);
}

TEST_F(StepperAllocationTest, CableWithEndCylinderGmresStepsDoNotAllocate) {
  const Scene scene = CableWithEndCylinder(LinearSolverKind::kGmres);
  ASSERT_FALSE(scene.cables.empty());
  ExpectStepsDoNotAllocate(scene, 0.005, 200);
}

TEST_F(StepperAllocationTest, SpatialCableWithSpunCylinderStepsDoNotAllocate) {
  // The spatial model: 12-coordinate elements, a body in natural
  // coordinates with its six axis rows, a spherical pin, a FIXED joint and a
  // torque on the body.
  Scene scene = CableWithEndCylinder(LinearSolverKind::kMinres);
  ASSERT_FALSE(scene.bodies.empty());
  scene.initial_velocity.angular_rad_s = Eigen::Vector3d(0, 4, 0);
  LoadSpec torque;
  torque.at.body = 0;
  torque.torque_nm = Eigen::Vector3d(1e-4, 0, 2e-4);
  scene.loads.push_back(torque);
  {
    auto model = MultibodyModel::Build(scene);
    ASSERT_TRUE(model.ok()) << model.status();
    ASSERT_EQ(model->dimension(), 3);
  }
  ExpectStepsDoNotAllocate(scene, 0.005, 200);
}

// Damping (cable Kelvin-Voigt and Rayleigh, body linear and angular) in
// every stepper, planar and spatial.
TEST_F(StepperAllocationTest, DampedStepsDoNotAllocate) {
  for (Integrator integrator :
       {Integrator::kImplicitEuler, Integrator::kGeneralizedAlpha, Integrator::kHht}) {
    for (bool spatial : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "integrator " << static_cast<int>(integrator)
                                        << " spatial " << spatial);
      Scene scene = CableWithEndCylinder(LinearSolverKind::kMinres);
      ASSERT_FALSE(scene.bodies.empty());
      scene.solver.Use(integrator);
      if (spatial) scene.initial_velocity.angular_rad_s = Eigen::Vector3d(0, 4, 0);
      CableSpec& cable = scene.cables[0];
      cable.axial_damping_s = 1e-3;
      cable.bending_damping_s = 2e-3;
      cable.rayleigh_alpha_1_s = 0.5;
      cable.rayleigh_beta_s = 1e-4;
      scene.bodies[0].linear_damping_n_s_m = 0.1;
      scene.bodies[0].angular_damping_n_m_s = 1e-3;
      ExpectStepsDoNotAllocate(scene, 0.005, 50);
    }
  }
}

}  // namespace
}  // namespace cablesim

namespace cablesim {
namespace {

// Three coincident 100-element cables pinned together at every node: 404
// constraint rows, enough for Eigen's blocked LLT to want a workspace (it
// allocated here before the Schur complement got its own in-place Cholesky).
TEST_F(StepperAllocationTest, ManyConstraintRowsDoNotAllocate) {
  Scene scene;
  scene.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);
  for (int c = 0; c < 3; ++c) scene.cables.push_back(UnitCable("c" + std::to_string(c), 100));
  JointSpec ground;
  ground.a.cable = 0;
  scene.joints.push_back(ground);
  for (int k = 1; k <= 100; ++k) {
    for (int c = 0; c < 2; ++c) {
      JointSpec pin;
      pin.a.cable = c;
      pin.a.s_m = k / 100.0;
      pin.b.cable = c + 1;
      pin.b.s_m = k / 100.0;
      scene.joints.push_back(pin);
    }
  }
  // 400 rows from the pins along the cables, plus two cables' first nodes
  // pinned to the grounded one's (which has no unknowns there: those rows
  // keep only the free side).
  JointSpec first01, first12;
  first01.a.cable = 0, first01.b.cable = 1;
  first12.a.cable = 1, first12.b.cable = 2;
  scene.joints.push_back(first01);
  scene.joints.push_back(first12);
  scene.solver.step_s = 1e-3;
  scene.solver.Use(Integrator::kImplicitEuler);
  absl::StatusOr<MultibodyModel> model = MultibodyModel::Build(scene);
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_GE(model->multipliers(), 400);
  ExpectStepsDoNotAllocate(scene, 1e-3, 3);
  // And with the second-order steppers and the direct solver.
  for (Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kHht}) {
    for (LinearSolverKind ls : {LinearSolverKind::kMinres, LinearSolverKind::kDirect}) {
      scene.solver.Use(integrator);
      scene.solver.linear_solver = ls;
      ExpectStepsDoNotAllocate(scene, 1e-3, 3);
    }
  }
}

// Generalized-alpha and HHT, every linear solver, with and without
// factorization reuse, on the falling pendulum (no multipliers) and the
// cable with an end cylinder (3 multipliers).
TEST_F(StepperAllocationTest, AlphaSteppersDoNotAllocate) {
  for (Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kHht}) {
    for (LinearSolverKind ls : {LinearSolverKind::kMinres, LinearSolverKind::kGmres,
                                LinearSolverKind::kDirect, LinearSolverKind::kAuto}) {
      for (bool reuse : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "integrator " << static_cast<int>(integrator)
                                        << " solver " << static_cast<int>(ls) << " reuse "
                                        << reuse);
        Scene pendulum = FallingPendulum();
        pendulum.solver.Use(integrator);
        pendulum.solver.linear_solver = ls;
        pendulum.solver.reuse_factorization = reuse;
        ExpectStepsDoNotAllocate(pendulum, 1e-3, 50);
        Scene cylinder = CableWithEndCylinder(ls);
        cylinder.solver.Use(integrator);
        cylinder.solver.reuse_factorization = reuse;
        ExpectStepsDoNotAllocate(cylinder, 0.005, 50);
      }
    }
  }
}

// The energy-momentum stepper likewise, every linear solver, with and
// without keeping its Newton matrix.
TEST_F(StepperAllocationTest, EnergyMomentumStepperDoesNotAllocate) {
  for (LinearSolverKind ls : {LinearSolverKind::kMinres, LinearSolverKind::kGmres,
                              LinearSolverKind::kDirect, LinearSolverKind::kAuto}) {
    for (bool reuse : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "solver " << static_cast<int>(ls) << " reuse "
                                        << reuse);
      Scene pendulum = FallingPendulum();
      pendulum.solver.Use(Integrator::kEnergyMomentum);
      pendulum.solver.linear_solver = ls;
      pendulum.solver.reuse_factorization = reuse;
      ExpectStepsDoNotAllocate(pendulum, 1e-3, 50);
      Scene cylinder = CableWithEndCylinder(ls);
      cylinder.solver.Use(Integrator::kEnergyMomentum);
      cylinder.solver.reuse_factorization = reuse;
      ExpectStepsDoNotAllocate(cylinder, 0.005, 50);
    }
  }
}

// Time dependence costs no allocation either: the crane sample (a support
// moving harmonically in x and y, rheonomic rows re-evaluated each step)
// with a time-varying force on the rope and a time-varying torque on the
// hook, in every stepper.
TEST_F(StepperAllocationTest, MovingSupportAndVaryingLoadsDoNotAllocate) {
  Scene scene = SampleScene("crane-trolley-hoist.json");
  ASSERT_FALSE(scene.cables.empty());
  LoadSpec load;
  load.at.cable = 0;
  load.at.s_m = 5;
  load.varying_force_n[0] = TimeFunction::Sine(10, 0.5, 0);
  scene.loads.push_back(load);
  LoadSpec torque;
  torque.at.body = 0;
  torque.varying_torque_nm[2] = TimeFunction::Table({0, 1}, {0, 5});
  scene.loads.push_back(torque);
  for (Integrator integrator :
       {Integrator::kImplicitEuler, Integrator::kGeneralizedAlpha, Integrator::kHht,
        Integrator::kEnergyMomentum}) {
    SCOPED_TRACE(::testing::Message() << "integrator " << static_cast<int>(integrator));
    scene.solver.Use(integrator);
    ExpectStepsDoNotAllocate(scene, 1e-3, 50);
  }
}

// A buoyant riser pinned at the bed in a regular wave and a JONSWAP sea,
// with drag and added mass.
Scene RiserInWaves() {
  return testing::SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": 1025, "current": {"x": 0.2}, "water_depth": 20,
              "waves": {"regular": [{"height": 2, "period": 8}],
                        "jonswap": [{"significant_height": 1, "peak_period": 6, "components": 10}]}},
    "cables": [{"name": "riser", "points": [{"y": -20}, {"y": -1}], "elements": 19,
                "density": 500, "youngs_modulus": 1e9, "diameter": 0.1,
                "hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.1, "added_mass": 1}}],
    "joints": [{"type": "PIN", "a": {"cable": "riser", "s": 0}}],
    "solver": {"duration": 1}})");
}

// Waves neither (engine/forces/wave_load.h: the flow at the Gauss points in
// arrays on the stack): a buoyant riser pinned at the bed in a regular wave
// and a JONSWAP sea, with drag and added mass, in every stepper.
TEST_F(StepperAllocationTest, WavesDoNotAllocate) {
  Scene scene = RiserInWaves();
  ASSERT_TRUE(scene.fluid.waves.any());
  ExpectEveryStepperDoesNotAllocate(scene, 0.01, 50);
}

// The explicit steppers (no Newton; stages in vectors sized once) neither:
// the falling pendulum, and the riser in waves (drag, added mass, a flow
// that varies in time) at a step within their stability limit.
TEST_F(StepperAllocationTest, ExplicitSteppersDoNotAllocate) {
  Scene riser = RiserInWaves();
  for (Integrator integrator : {Integrator::kDormandPrince, Integrator::kCentralDifference}) {
    SCOPED_TRACE(::testing::Message() << "integrator " << IntegratorName(integrator));
    // The scene's step is the one Initialize checks against the stability
    // limit; the steps taken are h.
    Scene pendulum = FallingPendulum();
    pendulum.solver.Use(integrator);
    pendulum.solver.step_s = 5e-4;
    ExpectStepsDoNotAllocate(pendulum, 5e-4, 50);
    riser.solver.Use(integrator);
    riser.solver.step_s = 1e-4;
    ExpectStepsDoNotAllocate(riser, 1e-4, 50);
  }
}

// Central difference with constraint rows (RATTLE: the rows' matrix S and
// its dense LDL^T sized once): the end cylinder (planar, a FIXED joint)
// and the same spun in space (a body's six axis rows), and the crane's
// moving trolley with its bodies, within the stable step.
TEST_F(StepperAllocationTest, CentralDifferenceWithConstraintRowsDoesNotAllocate) {
  Scene planar = CableWithEndCylinder(LinearSolverKind::kAuto);
  planar.solver.Use(Integrator::kCentralDifference);
  planar.solver.step_s = 4e-5;
  ExpectStepsDoNotAllocate(planar, 4e-5, 100);
  Scene spatial = planar;
  spatial.initial_velocity.angular_rad_s = Eigen::Vector3d(0, 4, 0);
  ExpectStepsDoNotAllocate(spatial, 4e-5, 100);
  // A moving support (the trolley) and bodies: rheonomic rows.
  Scene crane = SampleScene("crane-trolley-hoist.json");
  crane.solver.Use(Integrator::kCentralDifference);
  crane.solver.linear_solver = LinearSolverKind::kAuto;
  crane.solver.step_s = 2e-5;
  ExpectStepsDoNotAllocate(crane, 2e-5, 100);
}

// Nor bodies on the seabed (contact points in fixed-size blocks): a block
// laid at its resting depth slides on a damped, frictional bed, pulled at
// the contact level by its friction force (so it keeps sliding: the
// stick-slip transition at this step costs Newton failures, whose messages
// allocate).
TEST_F(StepperAllocationTest, BodyOnTheSeabedDoesNotAllocate) {
  Scene scene = testing::SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "bodies": [{"name": "block", "mass": 1000, "inertia": {"x": 100, "y": 120, "z": 110},
                "position": {"y": 0.499509},
                "seabed_contact": {"points": [{"x": -0.5, "y": -0.5}, {"x": 0.5, "y": -0.5}],
                                   "stiffness": 1e7, "damping": 1e4, "friction": 0.5}}],
    "loads": [{"at": {"body": "block", "point": {"y": -0.5}}, "force": {"x": 4905}}],
    "initial_velocity": {"linear": {"x": 0.3}},
    "seabed": {"stiffness": 1e6},
    "solver": {"duration": 1}})");
  ExpectEveryStepperDoesNotAllocate(scene, 0.01, 50);
}

// A rope pinned at both ends sagging onto a wheel under its middle, with
// friction and damping (the contact's pieces and Gauss points live on the
// stack).
TEST_F(StepperAllocationTest, SheaveContactDoesNotAllocate) {
  Scene scene = testing::SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "rope", "points": [{"x": -1, "y": 0.1}, {"x": 1, "y": 0.1}],
                "elements": 20, "density": 1000, "youngs_modulus": 1e9, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}},
               {"type": "PIN", "a": {"cable": "rope", "s": 2}}],
    "sheaves": [{"radius": 0.1, "friction": 0.3, "damping": 10}],
    "solver": {"duration": 1}})");
  ASSERT_EQ(scene.sheaves.size(), 1u);
  ExpectEveryStepperDoesNotAllocate(scene, 0.001, 50);
}


// Nor the fluid's loads on a body (engine/forces/body_fluid_load.h): a
// floating buoy with drag and added mass on a riser, in a regular wave,
// with a second part (a rod clamped along the body's y axis).
TEST_F(StepperAllocationTest, BodyHydrodynamicsDoNotAllocate) {
  Scene scene = testing::SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": 1025, "current": {"x": 0.2}, "water_depth": 20,
              "waves": {"regular": [{"height": 2, "period": 8}]}},
    "cables": [{"name": "riser", "points": [{"y": -20}, {"y": 0}], "elements": 10,
                "density": 500, "youngs_modulus": 1e9, "diameter": 0.1}],
    "bodies": [{"name": "buoy", "mass": 2000, "inertia": {"x": 100, "y": 100, "z": 100},
                "hydrodynamics": {"diameter": 2, "height": 2, "drag_coefficient": 1,
                                  "heave_drag_coefficient": 2, "added_mass": 1,
                                  "heave_added_mass": 0.5},
                "hydrodynamics_parts": [{"diameter": 0.3, "height": 3, "drag_coefficient": 1.2,
                                         "heave_drag_coefficient": 0.6, "added_mass": 1,
                                         "along_axis": true, "axis": {"y": 1}}]}],
    "joints": [{"type": "PIN", "a": {"cable": "riser", "s": 0}},
               {"type": "PIN", "a": {"cable": "riser", "s": 20}, "b": {"body": "buoy"}}],
    "solver": {"duration": 1}})");
  ExpectEveryStepperDoesNotAllocate(scene, 0.01, 50);
}

}  // namespace
}  // namespace cablesim
