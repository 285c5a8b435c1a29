// arbor: all rigid-body dynamics algorithms.
#pragma once

#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/cholesky.hpp"
#include "arbor/dynamics/crba.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/minverse.hpp"
#include "arbor/dynamics/payload.hpp"
#include "arbor/dynamics/rnea.hpp"
