"""ipfric_core: the physics, design, analysis, studies and identification of ipfric, without ROS.

Layers, each importing only those before it:
constants < physics < {analysis, design} < run < study < ident < cli; ``cli`` parses the
command line and prints.
"""

__all__ = ['constants', 'physics', 'analysis', 'design', 'run', 'study', 'ident', 'cli']
