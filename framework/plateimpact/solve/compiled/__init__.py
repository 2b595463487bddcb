"""The compiled path: the driver's algorithm for one scene at a time, compiled by numba
and run over the batch in parallel, wherever the model's plug-ins provide kernels
(:mod:`plateimpact.model.kernels`) and the integrator is an embedded Runge–Kutta pair.

The same steps, events and outcomes as the numpy driver (:mod:`plateimpact.solve.driver`),
from the same formulas: ``motion`` is the right-hand side and the margins, ``stepping``
the step and its control, ``events`` the event location, ``scene`` one scene from first
contact to its outcome; ``program`` builds and caches the compiled program and
``engine`` runs a batch on it. docs/integrators.md ("The compiled path") gives the
measurements."""
