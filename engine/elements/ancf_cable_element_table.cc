// The TABLE law's elastic force loop (ancf_cable_element_force.h says why
// it is instantiated in a file of its own).

#include "engine/elements/ancf_cable_element.h"
#include "engine/elements/ancf_cable_element_force.h"

namespace cablesim {

template void AncfCableElement<2>::ElasticForceWith<AxialLaw::kTable>(
    const Coords&, Coords*, Matrix*, Coords*) const;
template void AncfCableElement<3>::ElasticForceWith<AxialLaw::kTable>(
    const Coords&, Coords*, Matrix*, Coords*) const;
template void AncfCableElement<2>::ElasticForceWith<AxialLaw::kViscoelastic>(
    const Coords&, Coords*, Matrix*, Coords*) const;
template void AncfCableElement<3>::ElasticForceWith<AxialLaw::kViscoelastic>(
    const Coords&, Coords*, Matrix*, Coords*) const;

}  // namespace cablesim
