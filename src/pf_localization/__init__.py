"""pf_localization's Python tools, one module each, behind the commands of the same package
(scripts/NAME, installed as rosrun pf_localization NAME):

  evaluate   pf_evaluate: a run's accuracy against a reference, with plots
  tune       pf_tune: parameter tuning on bags with Optuna, on Dask
  benchmark  benchmark_datasets: the runner and evaluation over every recording with a reference
  cluster    the Dask client that tune and benchmark run their tasks on
  locate     where a tool finds pf_bag_runner and the package's files

catkin_python_setup() installs it (setup.py). In a devel space this package also holds
dynamic_reconfigure's generated pf_localization.cfg (catkin merges the two folders).
"""
