#include "convert/scene/sections.h"

#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace cablesim::scene_convert {

// How deep TimeFunction.sum and .product may nest.
constexpr int kMaxTimeFunctionDepth = 8;

absl::StatusOr<TimeFunction> ConvertTimeFunction(const std::string& path, const v1::TimeFunction& p,
                                                 const PlausibleRange& range, int depth) {
  TimeFunction f;
  const PlausibleRange slope{range.lo, range.hi, "per s"};
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "constant"), p.constant(), range));
  f.set_constant(p.constant());
  if (p.has_table()) {
    const std::string table = Sub(path, "table");
    const auto& times = p.table().times();
    const auto& values = p.table().values();
    if (times.empty()) return Invalid(Sub(table, "times"), "must have at least one entry");
    if (values.size() != times.size()) {
      return Invalid(Sub(table, "values"),
                     absl::StrCat("must have as many entries as times (", times.size(), "; got ",
                                  values.size(), ")"));
    }
    for (int k = 0; k < times.size(); ++k) {
      CABLESIM_RETURN_IF_ERROR(CheckRange(Indexed(table, "times", k), times[k], plausible::kTime));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Indexed(table, "values", k), values[k], range));
      if (k > 0 && !(times[k] > times[k - 1])) {
        return Invalid(Sub(table, "times"),
                       absl::StrCat("times must increase (times[", k, "] = ", Num(times[k]),
                                    " after ", Num(times[k - 1]), ")"));
      }
    }
    f.set_table({times.begin(), times.end()}, {values.begin(), values.end()});
  }
  if (p.has_harmonic()) {
    const std::string h = Sub(path, "harmonic");
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(h, "amplitude"), p.harmonic().amplitude(), range));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(h, "frequency"), p.harmonic().frequency()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange(Sub(h, "frequency"), p.harmonic().frequency(), plausible::kFrequency));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(h, "phase"), p.harmonic().phase(), plausible::kPhase));
    f.add_harmonic({p.harmonic().amplitude(), p.harmonic().frequency(), p.harmonic().phase()});
  }
  if (p.has_ramp()) {
    const std::string r = Sub(path, "ramp");
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(r, "slope"), p.ramp().slope(), slope));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(r, "start"), p.ramp().start()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(r, "start"), p.ramp().start(), plausible::kDuration));
    f.add_ramp({p.ramp().slope(), p.ramp().start()});
  }
  // The nested functions of `sum` (added) and `product` (multiplied). A
  // product's factor is dimensionless or in the quantity's unit: each must
  // be finite, which the quantity's range (wider than any factor's) checks.
  auto nested = [&](const char* field, const auto& functions)
      -> absl::StatusOr<std::vector<TimeFunction>> {
    std::vector<TimeFunction> out;
    for (int i = 0; i < functions.size(); ++i) {
      const std::string sub = Indexed(path, field, i);
      if (depth + 1 >= kMaxTimeFunctionDepth)
        return Invalid(sub, absl::StrCat("at most ", kMaxTimeFunctionDepth,
                                         " levels of sum and product"));
      CABLESIM_ASSIGN_OR_RETURN(TimeFunction g,
                                ConvertTimeFunction(sub, functions[i], range, depth + 1));
      out.push_back(std::move(g));
    }
    return out;
  };
  CABLESIM_ASSIGN_OR_RETURN(std::vector<TimeFunction> terms, nested("sum", p.sum()));
  for (TimeFunction& term : terms) f.add_term(std::move(term));
  CABLESIM_ASSIGN_OR_RETURN(std::vector<TimeFunction> factors, nested("product", p.product()));
  f.add_product(std::move(factors));
  return f;
}

absl::StatusOr<TimeVector> ConvertTimeVector(const std::string& path, const v1::TimeVec3& p,
                                             const PlausibleRange& range) {
  TimeVector v;
  CABLESIM_ASSIGN_OR_RETURN(v[0], ConvertTimeFunction(Sub(path, "x"), p.x(), range));
  CABLESIM_ASSIGN_OR_RETURN(v[1], ConvertTimeFunction(Sub(path, "y"), p.y(), range));
  CABLESIM_ASSIGN_OR_RETURN(v[2], ConvertTimeFunction(Sub(path, "z"), p.z(), range));
  return v;
}

}  // namespace cablesim::scene_convert
