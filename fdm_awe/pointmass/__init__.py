"""The point-mass model of the glider (eqs. 10/13): aerodynamics per configuration, the
propeller, frames and the math shared with the optimiser (numeric and CasADi)."""
