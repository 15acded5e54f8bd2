"""Explicit Runge–Kutta steps: the fixed step, looped and generated (:mod:`.steps`), the
step-size control of the embedded pairs (:mod:`.control`) and the adaptive loop of one
trajectory with its generated attempted step (:mod:`.adaptive`)."""
