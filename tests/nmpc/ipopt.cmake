# The converged NMPC solutions against IPOPT on the same discretised NLPs (host only; IPOPT is a
# test-only dependency, support/ipopt_reference.hpp): the pendulum and the cart-pole swing-ups,
# and the 2-DoF arm of examples/robots/double_pendulum.urdf (analytical and AutoDiff providers).
if(ARBOR_IPOPT_REFERENCE)
  arbor_add_test(nmpc_ipopt_pendulum_test SOURCES ipopt_pendulum_test.cpp
                 LIBS arbor_ipopt_reference LABELS nmpc)
  arbor_add_test(nmpc_ipopt_cartpole_test SOURCES ipopt_cartpole_test.cpp
                 LIBS arbor_ipopt_reference LABELS nmpc)
  if(ARBOR_HAVE_ROBOTS)
    arbor_add_test(nmpc_ipopt_arm_test SOURCES ipopt_arm_test.cpp
                   LIBS arbor_ipopt_reference arbor_robot_double_pendulum LABELS nmpc)
    # exact Hessians (RBD calls at nested duals): one provider per test (compile memory)
    arbor_add_test(nmpc_ipopt_arm_exact_analytical_test SOURCES ipopt_arm_exact_test.cpp
                   LIBS arbor_ipopt_reference arbor_robot_double_pendulum LABELS nmpc)
    arbor_add_test(nmpc_ipopt_arm_exact_autodiff_test SOURCES ipopt_arm_exact_test.cpp
                   LIBS arbor_ipopt_reference arbor_robot_double_pendulum LABELS nmpc)
    target_compile_definitions(nmpc_ipopt_arm_exact_autodiff_test PRIVATE ARM_EXACT_AUTODIFF)
  endif()
endif()
