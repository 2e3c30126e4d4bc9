from setuptools import find_packages, setup

package_name = 'ipfric_ros'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    package_data={'ipfric_ros': ['fastdds.xml']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='ipfric maintainers',
    maintainer_email='maintainers@ipfric.org',
    description='Topic names, QoS and scenario parameters shared by the ipfric ROS 2 nodes.',
    license='Apache-2.0',
    entry_points={'console_scripts': []},
)
