"""Solving: the integrator contract (a stepper and its dense output), the driver that runs
any stepper over a batch (events, failure, the 180-degree hold, rest, step-size control,
recording) and the equations of motion it integrates. It imports base and model."""
