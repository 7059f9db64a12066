# The pf_localization Python package (src/pf_localization: pf_evaluate, pf_tune,
# benchmark_datasets), for catkin_python_setup() in CMakeLists.txt; not for pip.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=['pf_localization'], package_dir={'': 'src'}))
