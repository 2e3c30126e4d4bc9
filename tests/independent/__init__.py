"""Independent test data for ipfric's system identification.

``rigsim`` simulates the cart-pendulum rig from the physics alone (it shares no
code with ``ipfric_core``) and writes CSV files plus a manifest of the true
parameters and the undeclared effect in each file. ``campaign`` draws such cases
at random (rig, effect and its size, experiment, sampling, encoders), with its own
integrator, and measures each effect's contribution in encoder counts; the scorer
is ``bench/ident_campaign.py``.
"""

__all__ = ["campaign", "rigsim"]
