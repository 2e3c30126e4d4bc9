"""Public logs of real cart and cart-pendulum rigs, converted for ``./ipfric identify`` (no data kept here)."""
