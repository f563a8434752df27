/// \file
/// \brief The convergence module of chapter 3 has no code outside its exercise: observed_order()
/// is defined in solutions/03-smooth-references/convergence.cpp (Exercise 3.3), and the studies
/// themselves live in the tests and the chapter's demos.

#include "grbd/ode/convergence.hpp"
