// arbor: first-order analytical derivatives of the rigid-body algorithms.
#pragma once

#include "arbor/derivatives/aba_derivatives.hpp"
#include "arbor/derivatives/frame_derivatives.hpp"
#include "arbor/derivatives/rnea_derivatives.hpp"
