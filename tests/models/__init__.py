"""Helper models of the tests: an affine system with an exactly linear residual law, a
linear nonholonomic system, and a unit pendulum whose pieces a test can replace."""
