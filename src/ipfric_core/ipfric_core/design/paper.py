
__all__ = ['GAIN_15_VISCOUS', 'GAIN_23_EXPONENTIAL', 'GAIN_25_DYNAMIC', 'EIG_DYNAMIC_GAIN_15', 'EIG_DYNAMIC_GAIN_25',
           'DELTA_UNSTABLE_ABOVE', 'DELTA_COMPLEX_UNTIL', 'TAU_C_EXPONENTIAL', 'TAU_C_DYNAMIC', 'MU_S', 'MU_C', 'EPS',
           'BREAKAWAY_MEAN_V']
"""Numbers printed in Campbell, Crawford, Morris, for side-by-side comparison.

Only printed values live here (as printed, with their equation numbers); every value
ipfric reports is computed from ``config/paper.yaml`` and the data files.
"""

GAIN_15_VISCOUS = (70.7107, 142.5409, 50.6911, 26.9817)            # eq. (15), eps = 2.1
GAIN_23_EXPONENTIAL = (70.7107, 304.9273, 143.3152, 61.0833)       # eq. (23)
GAIN_25_DYNAMIC = (85.0828, 290.4957, 136.0180, 58.1005, 0.0)      # eq. (25)
REDUCED_GAIN_DYNAMIC = (136.0180, -124.0216, -58.1005, 288.9371)   # K' of section 4.2

EIG_DYNAMIC_GAIN_15 = (0.0, -118.4231342, -5.326811579,
                       complex(-0.1396838407, 0.06683092600), complex(-0.1396838407, -0.06683092600))
EIG_DYNAMIC_GAIN_25 = (0.0, -92.38161062, -9.394053324, -4.632006064, -0.1744814929)

DELTA_UNSTABLE_ABOVE = 60.4     # section 3.1: two RHP roots for delta > 60.4
DELTA_COMPLEX_UNTIL = 241.0     # ... a complex pair for 60.4 < delta <= 241
TAU_C_EXPONENTIAL = 0.1069      # section 5.1, delta = 100, gain (23) [s]
TAU_C_DYNAMIC = 0.1169          # section 5.2, gain (25) [s]

MU_S = 0.08328                  # Table 2 / appendix 7.2 (printed ".8328" in the text)
MU_C = 0.04287                  # Table 2 / appendix 7.1
EPS = 2.3156                    # Table 2 / appendix 7.1 [N s/m]
BREAKAWAY_MEAN_V = 0.38697      # appendix 7.2 [V]
