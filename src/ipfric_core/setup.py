from setuptools import find_packages, setup

package_name = 'ipfric_core'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    # what the core imports (versions pinned in the checkout's requirements.txt)
    install_requires=['setuptools', 'numpy', 'scipy', 'pyyaml', 'numba', 'control', 'matplotlib', 'mcap',
                      'mcap-ros2-support', 'zstandard', 'lz4'],
    # --scheduler ADDRESS: sweeps, Monte Carlo and continuation on a Dask cluster
    extras_require={'cluster': ['dask', 'distributed']},
    zip_safe=True,
    maintainer='ipfric maintainers',
    maintainer_email='maintainers@ipfric.org',
    description='Physics, design, run supervision, studies, analysis and identification of ipfric (no ROS).',
    license='Apache-2.0',
    entry_points={'console_scripts': []},
)
