"""Independent test data for ipfric's system identification.

``rigsim`` simulates the cart-pendulum rig from the physics alone (it shares no
code with ``ipfric_core``) and writes CSV files plus a manifest of the true
parameters and the undeclared effect in each file.
"""

__all__ = ["rigsim"]
