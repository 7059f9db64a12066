"""pf_localization's Python tools, one module each, behind the commands of the same package
(scripts/NAME, installed as rosrun pf_localization NAME):

  evaluate   pf_evaluate: the command line and the report (summary.json, the text summary), from
             its parts:
    evaluate_inputs     reading the trajectory, the reference, the runner's logs and the map
    evaluate_reference  the error against a reference: ATE, rigid fit, covariance honesty, hypotheses
    self_assessment     what the filter knows without a reference: fit, verdict, covariance size
    map_changes         the map's changes layer, scored against the true mask
    scans_at_estimate   the bag's scans drawn at the estimate, the laser's mounting from /tf
    report_plots        the figures and the particle GIF
  tune       pf_tune: parameter tuning on bags with Optuna, on Dask
  benchmark  benchmark_datasets: the runner and evaluation over every recording with a reference
  cluster    the Dask client that tune and benchmark run their tasks on
  locate     where a tool finds pf_bag_runner and the package's files

catkin_python_setup() installs it (setup.py). In a devel space this package also holds
dynamic_reconfigure's generated pf_localization.cfg (catkin merges the two folders).
"""
