from setuptools import find_packages, setup

package_name = 'ipfric_record'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools', 'mcap', 'rosbags', 'pyyaml'],
    zip_safe=True,
    maintainer='ipfric maintainers',
    maintainer_email='maintainers@ipfric.org',
    description='Records an ipfric run into a rosbag2 MCAP directory.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'recorder = ipfric_record.recorder:main',
        ],
    },
)
