// The weak directions of the kinematic bundle adjustment held at the robot description's value, before the
// fit (each joint parameter given the ones before it, at the stated pixel noise) and after it (what the
// estimated pose error per image leaves poorly determined): BundleOptions::weak_length_tolerance_m,
// weak_angle_tolerance_rad; the parameters held are named in BundleReport::weak.
#pragma once

#include "bundle/bundle_adjustment.h"
#include "bundle/bundle_problem.h"

namespace selfcal::bundle::internal {

// Holds the joint parameters the poses determine worse than their tolerance at the stated pixel noise,
// judged at the nominal model; the state's values move there. False when it cannot be evaluated there.
bool HoldWeakAtNominal(const BundleData& data, const BundleOptions& options, Gauge* gauge, BundleState* state,
                       BundleReport* report);

// After a fit whose error model shows a pose error: holds the one free joint parameter whose standard
// deviation under that model exceeds its tolerance by the most (mostly through the pose error: the pixel
// noise alone would not);
// true when one was, and the caller refits and asks again.
bool HoldWeakestUnderErrorModel(const BundleData& data, const BundleOptions& options, Gauge* gauge,
                                BundleState* state, BundleReport* report);

}  // namespace selfcal::bundle::internal
