from setuptools import find_packages, setup

package_name = 'ipfric_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools', 'numpy'],
    zip_safe=True,
    maintainer='ipfric maintainers',
    maintainer_email='maintainers@ipfric.org',
    description='Simulated friction cart-pendulum rig node (lockstep or real time).',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'sim_node = ipfric_sim.sim_node:main',
        ],
    },
)
