"""External axes along a seam: the positioner's and the track's motion the planner chooses.

A case with a track or a positioner (:class:`~trackplan.robots.machine.Machine`) plans every
seam with a profile of its external axes over the planned path's arc length
(:class:`~trackplan.axes.profile.AxesProfile`): the positioner turns the part so that the
weld stays downhand (:class:`~trackplan.axes.rules.Downhand`), and the track carries the arm
along the seam (``docs/positioner.md``).
"""
