// arbor: analytical derivatives of the rigid-body algorithms: first order (rnea, aba, frames) and
// second order (Hessians of lambda' ID and lambda' FD, and ID's four second-order tensors).
#pragma once

#include "arbor/derivatives/aba_derivatives.hpp"
#include "arbor/derivatives/aba_second_order.hpp"
#include "arbor/derivatives/frame_derivatives.hpp"
#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/derivatives/rnea_second_order.hpp"
#include "arbor/derivatives/rnea_second_order_tensors.hpp"
