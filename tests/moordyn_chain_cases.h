#ifndef CABLESIM_TESTS_MOORDYN_CHAIN_CASES_H_
#define CABLESIM_TESTS_MOORDYN_CHAIN_CASES_H_

// MoorDyn's three chain cases (its tests/Mooring/WD0050_Chain.txt,
// WD0200_Chain.txt, WD0600_Chain.txt; MoorDyn is BSD-3-Clause, (c) 2022
// Matt Hall; only the cases' numbers are carried, in a deck written here):
// the statics of tests/moordyn_chain_test.cc and the dynamics of
// tests/moordyn_chain_dynamic_slow_test.cc.

#include <string>

#include "absl/strings/str_format.h"

namespace cablesim {

struct ChainCase {
  double depth_m, anchor_x_m, length_m;
  int segments;
  double orcaflex_kn;  // OrcaFlex's static fairlead tension
};

inline const ChainCase kChain50{50, 400, 410, 41, 991.6};
inline const ChainCase kChain200{200, 700, 760, 76, 2065.4};
inline const ChainCase kChain600{600, 1500, 1700, 170, 5232.6};

inline std::string ChainDeck(const ChainCase& c) {
  return absl::StrFormat(R"(--------------------- MoorDyn Input File ------------------------------------
Chain at %g m depth (numbers of MoorDyn's WD%04d_Chain case)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.252   390        1.674e9    -1.0        0          1.37   1.0    0.64    0.0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     %g      0.0     %g      0      0       0      0
2     Vessel    0.0     0.0     0.0     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      1        2         %g        %d      -
---------------------- OPTIONS -----------------------------------------
1.0e5                kBot                 bottom stiffness (Pa/m)
1.0e4                cBot                 bottom damping (Pa-s/m)
1025.0               WtrDnsty             water density (kg/m^3)
%g                   WtrDpth              water depth (m)
100.0                TmaxIC               max time for ic gen (s)
0.5                  FrictionCoefficient  general bottom friction coefficient (-)
---------------------- OUTPUTS -----------------------------------------
FairTen1
------------------------- need this line --------------------------------------
)",
                         c.depth_m, static_cast<int>(c.depth_m), c.anchor_x_m, -c.depth_m,
                         c.length_m, c.segments, c.depth_m);
}

}  // namespace cablesim

#endif  // CABLESIM_TESTS_MOORDYN_CHAIN_CASES_H_
