"""The ensemble kernels: fixed steps on blocks of members in lockstep (:mod:`.block`) and
adaptive steps with members on lanes (:mod:`.lanes`)."""
