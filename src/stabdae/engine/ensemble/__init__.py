"""The ensemble kernels: fixed steps on blocks of members in lockstep (:mod:`.block`) and
adaptive steps with members on lanes (:mod:`.lanes`), both taking their arguments in the
named groups of :mod:`.groups`."""
