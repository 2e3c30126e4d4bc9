"""ipfric_core: the physics, design, analysis and identification of ipfric, without ROS.

Layers, each importing only those before it:
constants < physics < design < run < analysis < ident; ``cli`` parses the command line and prints.
"""

__all__ = ['constants', 'physics', 'design', 'run', 'analysis', 'ident', 'cli']
