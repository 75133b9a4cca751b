#include "convert/plausibility_warnings.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string CablePath(const Scene& scene, int c) {
  return absl::StrCat("cables[", c, "]");
}

std::string Named(const Scene& scene, int c) {
  const std::string& name = scene.cables[c].name;
  return name.empty() ? CablePath(scene, c) : absl::StrCat(CablePath(scene, c), " '", name, "'");
}

// The bodies jointed directly to cable c (each once).
std::set<int> PayloadBodies(const Scene& scene, int c) {
  std::set<int> bodies;
  for (const JointSpec& j : scene.joints) {
    if (j.a.cable == c && j.b.body >= 0) bodies.insert(j.b.body);
    if (j.b.cable == c && j.a.body >= 0) bodies.insert(j.a.body);
  }
  return bodies;
}

// The magnitude of the loads at cable c or at one of `bodies`, at t = 0 [N].
double LoadOn(const Scene& scene, int c, const std::set<int>& bodies) {
  double sum = 0;
  for (const LoadSpec& l : scene.loads) {
    if (l.at.cable != c && !(l.at.body >= 0 && bodies.count(l.at.body) > 0)) continue;
    sum += (l.force_n + Evaluate(l.varying_force_n, 0)).norm();
  }
  return sum;
}

// The total length of the cables jointed to cable c, directly or through
// bodies, c included [m]: a chain cut into pieces by the bodies threaded on
// it (the paper's cylinders) is one cable for the 1/10 rule.
double ConnectedLength(const Scene& scene, int c) {
  const int n = static_cast<int>(scene.cables.size());
  // Union-find over the cables (0..n-1) and the bodies (n..).
  std::vector<int> parent(n + scene.bodies.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto node = [&](const Attachment& a) { return a.cable >= 0 ? a.cable : a.body >= 0 ? n + a.body : -1; };
  for (const JointSpec& j : scene.joints) {
    const int a = node(j.a), b = node(j.b);
    if (a >= 0 && b >= 0) parent[find(a)] = find(b);
  }
  double length = 0;
  for (int i = 0; i < n; ++i)
    if (find(i) == find(c)) length += scene.cables[i].length_m;
  return length;
}

}  // namespace

std::vector<std::string> PlausibilityWarnings(const v1::Scene& proto, const Scene& scene) {
  std::vector<std::string> out;
  const double g = scene.gravity_m_s2.norm();
  const SolverSettings& solver = scene.solver;
  const bool fixed_dynamic_step = solver.analysis == Analysis::kDynamic && !solver.adaptive;
  double shortest_period = INFINITY;
  std::string shortest_what;
  for (int c = 0; c < static_cast<int>(scene.cables.size()); ++c) {
    const CableSpec& cable = scene.cables[c];
    const std::string path = CablePath(scene, c);
    const double e = cable.youngs_modulus_pa, rho = cable.density_kg_m3;
    if (e < kPlausibleYoungsModulusLo || e > kPlausibleYoungsModulusHi) {
      out.push_back(absl::StrFormat(
          "%s.youngs_modulus: %g Pa is outside %g..%g Pa (soft rubber to diamond); it expects "
          "Pa (steel is 2e11 Pa: was it given in GPa or MPa?)",
          path, e, kPlausibleYoungsModulusLo, kPlausibleYoungsModulusHi));
    }
    if (rho < kPlausibleDensityLo || rho > kPlausibleDensityHi) {
      out.push_back(absl::StrFormat(
          "%s.density: %g kg/m^3 is outside %g..%g kg/m^3; it expects kg/m^3 (steel is 7850)",
          path, rho, kPlausibleDensityLo, kPlausibleDensityHi));
    }
    const bool by_diameter =
        c < proto.cables_size() && proto.cables(c).has_diameter() && !proto.cables(c).has_area();
    const double diameter = std::sqrt(4 * cable.area_m2 / kPi);
    const std::string size_field =
        by_diameter ? absl::StrFormat("%s.diameter %g m", path, diameter)
                    : absl::StrFormat("%s.area %g m^2 (diameter %g m)", path, cable.area_m2,
                                      diameter);
    const double length = cable.length_m;
    const int elements = std::max(cable.elements, 1);
    const double element = length / elements;
    if (element < diameter) {
      out.push_back(absl::StrFormat(
          "%s.elements: %d elements of %g m are shorter than the cable's diameter (%s): a cable "
          "element that short is not slender; check the diameter's units (m) or use fewer "
          "elements",
          path, elements, element, size_field));
    } else if (const double chain = ConnectedLength(scene, c); element > chain / 10 * (1 + 1e-12)) {
      out.push_back(absl::StrFormat(
          "%s.elements: %d elements of %g m are longer than 1/10 of the cable (%g m%s): its "
          "sag, bending and transverse waves are coarsely resolved; use more elements",
          path, elements, element, chain,
          chain > length ? ", with the cables jointed to it" : ""));
    }
    const double cable_mass = rho * cable.area_m2 * length;
    const std::set<int> bodies = PayloadBodies(scene, c);
    double payload = 0;
    for (int b : bodies) payload += scene.bodies[b].mass_kg;
    const double ea = e * cable.area_m2;
    const double load = LoadOn(scene, c, bodies);
    const double tension = g * (cable_mass + payload) + load;
    if (ea > 0 && tension / ea > kMaxStaticStrain) {
      out.push_back(absl::StrFormat(
          "%s: the static strain under its weight, payload and loads is about %.3g %% (%.3g N "
          "over EA %.3g N), above %g %%: check %s.youngs_modulus (%g Pa, expects Pa) and the "
          "section (%s)",
          Named(scene, c), 100 * tension / ea, tension, ea, 100 * kMaxStaticStrain, path, e,
          size_field));
    }
    if (payload > 0 && cable_mass > 0 &&
        (cable_mass > kWeightRatio * payload || payload > kWeightRatio * cable_mass)) {
      out.push_back(absl::StrFormat(
          "%s: its mass %.3g kg (density %g kg/m^3 x section %g m^2 x length %g m) is %.3g times "
          "its payload's %.3g kg (the bodies jointed to it): check %s.density (kg/m^3) and the "
          "section (%s)",
          Named(scene, c), cable_mass, rho, cable.area_m2, length, cable_mass / payload, payload,
          path, size_field));
    }
    if (fixed_dynamic_step && ea > 0) {
      // A viscoelastic line bounces on its dynamic stiffness EA_2 (at least
      // the mean-load law's at no load), stiffer than the static EA.
      double ea_bounce = ea;
      if (cable.axial_law == AxialLaw::kViscoelastic)
        ea_bounce = std::max(ea, cable.visco_dynamic_ea_n > 0 ? cable.visco_dynamic_ea_n
                                                               : cable.visco_dynamic_ea_base_n);
      const double period = 2 * kPi * std::sqrt((payload + cable_mass / 3) * length / ea_bounce);
      if (period < shortest_period) {
        shortest_period = period;
        shortest_what = absl::StrFormat("the axial bounce of %s with %.3g kg of payload",
                                        Named(scene, c), payload);
      }
    }
  }
  if (fixed_dynamic_step && solver.step_s > shortest_period) {
    out.push_back(absl::StrFormat(
        "solver.step: %g s is above the shortest period the scene's cables resolve, %.3g s (%s): "
        "its dynamic tension is not resolved; it expects seconds (was it given in ms?); use a "
        "step below %.3g s or solver.adaptive",
        solver.step_s, shortest_period, shortest_what, shortest_period));
  }
  return out;
}

}  // namespace cablesim
