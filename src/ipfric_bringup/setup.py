from glob import glob

from setuptools import setup

package_name = 'ipfric_bringup'

setup(
    name=package_name,
    version='0.1.0',
    packages=[],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
        ('share/' + package_name + '/plotjuggler', glob('plotjuggler/*.xml')),
        # the scenarios of the checkout's config/ (a symlink), found by name: scenario:=default
        ('share/' + package_name + '/config', sorted(f for f in glob('config/*.yaml') if not f.endswith('paper.yaml'))),
        ('share/' + package_name + '/urdf', glob('urdf/*.urdf')),
        ('share/' + package_name + '/rviz', glob('rviz/*.rviz')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='ipfric maintainers',
    maintainer_email='maintainers@ipfric.org',
    description='Launch file of an ipfric run, its scenarios, the cart-pendulum URDF, RViz and PlotJuggler layouts.',
    license='Apache-2.0',
)
