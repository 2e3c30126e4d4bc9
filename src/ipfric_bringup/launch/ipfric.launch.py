"""An ipfric run under ``ros2 launch``: recorder, controller_node and sim_node on one scenario.

    ros2 launch ipfric_bringup ipfric.launch.py scenario:=config/default.yaml out:=runs/l1 duration:=5.0

Arguments: ``scenario`` (parameter file, required), ``out`` (run directory; bag in
``out``/bag), and the run arguments of :data:`ipfric_core.run.nodes.OVERRIDES`
(``duration`` [s], ``time_mode``, ``theta0`` [rad], ``delay`` [s]), each replacing the scenario's
value only when given. The nodes get the parameters ``./ipfric run`` gives them
(:func:`ipfric_core.run.nodes.node_parameters`), so both runs record the same bag. The
launch ends when sim_node exits (duration reached, a limit crossed); controller and
recorder are then stopped with SIGINT and the bag is closed.
"""
import time
from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from ipfric_core.run.nodes import NODES, OVERRIDES, node_parameters, parse_overrides, write_run_scenario


def run_nodes(context):
    """The three node actions of the run (the scenario is validated and written first)."""
    def arg(name):
        return LaunchConfiguration(name).perform(context)
    out = Path(arg('out') or time.strftime('ipfric_launch_%Y%m%d_%H%M%S')).resolve()
    scenario = write_run_scenario(arg('scenario'), out, parse_overrides({k: arg(k) for k in OVERRIDES}))
    params = node_parameters(scenario, out)
    actions = []
    for name, (package, executable) in NODES.items():
        params_file, extra = params[name]
        actions.append(Node(package=package, executable=executable, name=name, output='screen',
                            parameters=([params_file] if params_file else []) + [extra],
                            on_exit=Shutdown(reason='sim_node ended') if name == 'sim_node' else None))
    return actions


def generate_launch_description():
    return LaunchDescription(
        [DeclareLaunchArgument('scenario', description='scenario parameter file (config/*.yaml)'),
         DeclareLaunchArgument('out', default_value='', description='run directory ("" = ipfric_launch_<time>)')]
        + [DeclareLaunchArgument(name, default_value='', description=f'{doc} ("" = the scenario\'s)')
           for name, (*_, doc) in OVERRIDES.items()]
        + [OpaqueFunction(function=run_nodes)])
