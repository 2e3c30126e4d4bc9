"""An ipfric run under ``ros2 launch``: recorder, controller_node and sim_node on one scenario.

    ros2 launch ipfric_bringup ipfric.launch.py scenario:=default out:=runs/l1 duration:=5.0
    ros2 launch ipfric_bringup ipfric.launch.py scenario:=fig9_new_gain_exponential namespace:=rig2 out:=runs/rig2

Arguments: ``scenario`` (a parameter file, or the name of a scenario installed in
``share/ipfric_bringup/config``), ``out`` (run directory; bag in ``out``/bag), ``namespace``
(the rig's: its topics, its clock, its nodes; several rigs share a ROS domain, each in its
namespace), ``robot_state_publisher`` (true: also start robot_state_publisher on the rig's
URDF, for TF and RViz), and the run arguments of :data:`ipfric_core.run.nodes.OVERRIDES`
(``duration`` [s], ``time_mode``, ``theta0`` [rad], ``delay`` [s]), each replacing the
scenario's value only when given. The nodes get the parameters ``./ipfric run`` gives them
(:func:`ipfric_core.run.nodes.node_parameters`), so both runs record the same bag. The
launch ends when sim_node exits (duration reached, a limit crossed); controller and
recorder are then stopped with SIGINT and the bag is closed. A Ctrl-C stops every node at
once: the simulator records ABORT and the recorder closes the bag after it.
"""
import time
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace

from ipfric_core.run.nodes import NODES, OVERRIDES, node_parameters, parse_overrides, write_run_scenario
from ipfric_core.run.scenario import check_namespace

URDF = 'urdf/cart_pendulum.urdf'


def run_nodes(context):
    """The node actions of the run (the scenario is validated and written first)."""
    def arg(name):
        return LaunchConfiguration(name).perform(context)
    namespace = check_namespace(arg('namespace'), 'namespace')
    out = Path(arg('out') or time.strftime('ipfric_launch_%Y%m%d_%H%M%S')).resolve()
    scenario = write_run_scenario(arg('scenario'), out, parse_overrides({k: arg(k) for k in OVERRIDES}), namespace)
    params = node_parameters(scenario, out)
    actions = []
    for name, (package, executable) in NODES.items():
        params_file, extra = params[name]
        actions.append(Node(package=package, executable=executable, name=name, output='screen',
                            parameters=([params_file] if params_file else []) + [extra],
                            on_exit=Shutdown(reason='sim_node ended') if name == 'sim_node' else None))
    if arg('robot_state_publisher').lower() == 'true':
        urdf = Path(get_package_share_directory('ipfric_bringup'), URDF).read_text()
        prefix = '' if namespace == '/' else namespace.strip('/') + '/'     # each rig's frames apart in /tf
        actions.append(Node(package='robot_state_publisher', executable='robot_state_publisher',
                            output='screen', parameters=[{'robot_description': urdf, 'frame_prefix': prefix}]))
    return [GroupAction([PushRosNamespace(namespace), *actions])] if namespace != '/' else actions


def generate_launch_description():
    return LaunchDescription(
        [DeclareLaunchArgument('scenario', description='scenario parameter file, or an installed scenario\'s name '
                                                       '(default, realtime, fig7_old_gain_exponential, ...)'),
         DeclareLaunchArgument('out', default_value='', description='run directory ("" = ipfric_launch_<time>)'),
         DeclareLaunchArgument('namespace', default_value='', description='the rig\'s ROS namespace ("" = the root)'),
         DeclareLaunchArgument('robot_state_publisher', default_value='false',
                               description='true: start robot_state_publisher on the cart-pendulum URDF (TF, RViz)')]
        + [DeclareLaunchArgument(name, default_value='', description=f'{doc} ("" = the scenario\'s)')
           for name, (*_, doc) in OVERRIDES.items()]
        + [OpaqueFunction(function=run_nodes)])
