"""Build script: an ament_python package that also installs with plain pip."""

from glob import glob
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = 'lumpbeam_ros'

#: What the offline commands need (reproduce, synth, analyze, diagnose, compare).
REQUIRES = ['setuptools', 'numpy', 'scipy', 'pyyaml', 'threadpoolctl', 'rosbags', 'mcap']

#: The rest, by what it serves (lumpbeam_ros/apps/cli/dependencies.py names them when missing).
EXTRAS = {
    # The lowest (make test runs the vision tests on it too: 4.10 is the first built for
    # NumPy 2) to the newest major the tests run on.
    'vision': ['opencv-python-headless>=4.10,<6'],
    'ros': ['ros-jazzy-rclpy[fastrtps]', 'ros-jazzy-common-interfaces'],
    'plots': ['matplotlib'],
    # lumpbeam campaign: the Dask cluster and the Parquet/CSV table.
    'campaign': ['dask', 'distributed', 'pyarrow'],
    # lumpbeam view: the Foxglove SDK's WebSocket server (MIT).
    'view': ['foxglove-sdk'],
}
EXTRAS['all'] = sorted({req for reqs in EXTRAS.values() for req in reqs})

setup(
    name=PACKAGE,
    version='0.1.0',
    # The product alone: what proves it (lumpbeam_lab/: benchmarks, validation renderers,
    # peers) stays in the repository, where `lumpbeam bench` finds it from a checkout.
    packages=find_packages(include=[PACKAGE, f'{PACKAGE}.*']),
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{PACKAGE}']),
        (f'share/{PACKAGE}', ['package.xml']),
        (
            f'share/{PACKAGE}/config',
            glob('config/*.yaml') + glob('config/*.json') + glob('config/*.rviz'),
        ),
        (f'share/{PACKAGE}/launch', glob('launch/*.launch.yaml')),
        (f'share/{PACKAGE}/examples', glob('examples/*.csv')),
    ],
    package_data={f'{PACKAGE}.base': ['data/*.csv', 'data/*.xml']},
    install_requires=REQUIRES,
    extras_require=EXTRAS,
    zip_safe=True,
    maintainer='lumpbeam_ros maintainers',
    maintainer_email='lumpbeam@example.org',
    description='Live tip tracking and online identification of flexible beams (ROS 2).',
    long_description=Path(__file__).with_name('README.md').read_text(encoding='utf-8'),
    long_description_content_type='text/markdown',
    license='Apache-2.0',
    python_requires='>=3.10',
    entry_points={
        'console_scripts': [
            'lumpbeam = lumpbeam_ros.apps.cli.script:lumpbeam',
            'identifier_node = lumpbeam_ros.nodes.scripts:identifier_node',
            'simulator_node = lumpbeam_ros.nodes.scripts:simulator_node',
            'camera_node = lumpbeam_ros.nodes.scripts:camera_node',
            'diagnosis_node = lumpbeam_ros.nodes.scripts:diagnosis_node',
            'shaper_node = lumpbeam_ros.nodes.scripts:shaper_node',
        ],
    },
)
