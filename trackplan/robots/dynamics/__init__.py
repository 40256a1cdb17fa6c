"""Robot dynamics: inverse dynamics (:mod:`.rne`) and the built-in parameters (:mod:`.builtin`);
the parameters themselves are :mod:`trackplan.robots.dynamics_parameters`, which the robot
model holds."""
