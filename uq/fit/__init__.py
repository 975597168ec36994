"""Wing: Bayesian and least-squares wind-profile fits (uq fit)."""
