"""The study floor: study files, grids of ensembles, their theory tables and summaries,
and the command line.  Built on the drivers (:func:`stabdae.ensemble`,
:func:`stabdae.integrate`) and on :mod:`stabdae.theory`; nothing below imports it."""
