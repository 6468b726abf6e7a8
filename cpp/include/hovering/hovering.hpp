#pragma once
// Umbrella header of the hovering core: both models of the return map and their bridge.
//
//   truncated/  the truncated near-tangency family F_{eps1,eps2} (eq:trunceps1eps2, eq:truncatedmap)
//   flow/       the oscillators-step flow (sec:setup) and its return map to Sigma_h
//   normal/     normal coordinates (phi, K) of the flow's section, and the flow as a map on them

#include "hovering/batch.hpp"
#include "hovering/simd.hpp"
#include "hovering/tangent.hpp"
#include "hovering/types.hpp"

#include "hovering/truncated/arcs.hpp"
#include "hovering/truncated/forcing.hpp"
#include "hovering/truncated/map.hpp"

#include "hovering/flow/potential.hpp"
#include "hovering/flow/return_map.hpp"
#include "hovering/flow/system.hpp"

#include "hovering/normal/flow_map.hpp"
#include "hovering/normal/tangential_curve.hpp"
