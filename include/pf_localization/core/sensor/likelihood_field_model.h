// The likelihood-field beam model: weighs each particle by how well the scan's
// end points, placed from that particle's pose, fall on the map's obstacles.
//
// Thrun, Burgard & Fox, "Probabilistic Robotics" (2005), table 6.3. For a beam
// whose end point lies dist metres from the nearest obstacle:
//   p = z_hit * N(dist; 0, sigma_hit) + z_rand / range_max
// Beams are independent, so a particle's log-likelihood is the sum of the
// beams' log p. Working in log space means no product of hundreds of small
// numbers can underflow to zero.
//
// log p depends only on the distance of the cell an end point falls in, so
// it is precomputed once per map (and per range_max): a map of up to
// DistanceField::kMaxFloatCells cells gets a float a cell, with a one-cell border that
// stands for "outside the map", and the per-beam work is: transform the end
// point, clamp the cell index into the table, add. A larger map's cells'
// distances take few values (the field keeps a class a cell:
// distance_field.h), so its table holds a value per class, a few thousand
// floats, and a beam reads its cell's class first: a second lookup, but no
// table of 4 bytes a cell per range_max (192 MB on a 200 x 600 m floor).
//
// Beam skipping (ROS amcl's likelihood_field_prob, in its
// AMCLLaser::LikelihoodFieldModelProb; not in Probabilistic Robotics): a beam
// that few particles place near an obstacle probably hit something the map
// does not have (a person, a moved box), and would only punish the particles
// at the true pose. For each beam, count the particles whose end point lies
// within beam_skip_distance of an obstacle; a beam is counted only when more
// than beam_skip_threshold of the particles agree with it, unless so many
// beams would be left out (at least beam_skip_error_threshold of them) that
// the filter is more likely wrong than the map, and then every beam counts.
// The particles are counted unweighted, as amcl does.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/likelihood_tables.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/parameter_table.h"

namespace pf {

struct LikelihoodFieldModelParams {
  double z_hit = 0.95;        // weight of the Gaussian hit component (unitless)
  double z_rand = 0.05;       // weight of the uniform random component (unitless)
  double sigma_hit = 0.2;     // std dev of the hit component (m)
  double max_distance = 2.0;  // distance field cap (m)
  int max_beams = 60;         // beams used per scan after dropping invalid ones
  double range_min = 0.0;     // m; tighter lower limit than the scan's, 0 = scan's
  double range_max = 0.0;     // m; tighter upper limit than the scan's, 0 = scan's
  // The beams of one scan are not independent (neighbours see the same wall,
  // the map is imperfect), so their plain product is far too confident: one
  // scan can make a single particle outweigh all others by e^100. Raising the
  // scan likelihood to this power (tempering) keeps rival hypotheses alive
  // until the evidence really separates them. 1 = independent beams.
  double likelihood_exponent = 0.2;  // (0, 1]
  // Threads scoring the particles (OpenMP builds): not a parameter of its
  // own, the filter's `threads` (makeSensorModel). Each particle is scored
  // on its own, so the result does not depend on this number.
  int threads = 1;
  // Beam skipping (see above; amcl's do_beamskip and beam_skip_*). Only
  // laser_model_type likelihood_field_prob turns it on, as in amcl.
  bool beam_skip = false;
  double beam_skip_distance = 0.5;         // m; an end point this close to an obstacle agrees (> 0)
  double beam_skip_threshold = 0.3;        // share of particles that must agree, in [0, 1]
  double beam_skip_error_threshold = 0.9;  // skip nothing when this share would be skipped, [0, 1]
};

/// The parameters of LikelihoodFieldModelParams (parameter_table.h); the
/// beam model shares them. beamSkipParameters() are the beam_skip_* ones,
/// checked only while do_beamskip is set.
const ParameterTable<LikelihoodFieldModelParams>& likelihoodFieldParameters();
const ParameterTable<LikelihoodFieldModelParams>& beamSkipParameters();

/// Throws std::invalid_argument naming the first parameter out of range
/// (likelihoodFieldParameters() and z_hit + z_rand > 0); the start-up check
/// (pf::validate) and the models' constructors share it.
void validate(const LikelihoodFieldModelParams& params);

class LikelihoodFieldModel : public SensorModel {
 public:
  /// How the tables are laid out: by the map's size (DistanceField::kMaxFloatCells),
  /// or either way whatever the size (for tests: the scores are the same).
  enum class TableLayout { kBySize, kPerCell, kPerClass };

  /// Throws std::invalid_argument naming the parameter when one is out of
  /// range. Its field keeps `grid` (moved in).
  LikelihoodFieldModel(OccupancyGrid grid, const LikelihoodFieldModelParams& params,
                       TableLayout layout = TableLayout::kBySize);

  const LikelihoodFieldModelParams& params() const { return params_; }
  const DistanceField& field() const override { return *field_; }

  /// This model with the hit component's std dev `sigma_hit`, on the same
  /// likelihood field (shared, not copied: only the table is its own).
  std::unique_ptr<SensorModel> smoothed(double sigma_hit) const override;

  /// The usable beams' end points in the robot frame.
  PreparedScan prepare(const LaserScan& scan) const override {
    return prepare(scan, params_.max_beams);
  }
  /// The same with another beam budget (<= 0: every usable beam).
  PreparedScan prepare(const LaserScan& scan, int max_beams) const override;

  /// likelihood_exponent * log p(scan | pose) for one pose (no beam skipping:
  /// that is a decision of the whole cloud).
  double logLikelihood(const PreparedScan& scan, const Pose2& pose) const override;

  /// likelihood_exponent * log p(scan | particle) for every particle, into
  /// `log_likelihood`, over the beams that beam skipping keeps (all when it
  /// is off). Returns how many beams were counted.
  std::size_t logLikelihoods(const PreparedScan& scan, const ParticleSet& particles,
                             std::vector<double>* log_likelihood) const override;

  /// Builds the table for scans of `range_max` (likelihood_tables.h).
  void warmUp(double range_max) const override { table(range_max); }
  /// Tables built so far, one per range_max scored (likelihood_tables.h).
  std::size_t tablesBuilt() const { return tables_.builds(); }

  /// log p of one beam whose end point is `distance` metres from an obstacle.
  double beamLogLikelihood(double distance, double range_max) const;

 private:
  LikelihoodFieldModel(const LikelihoodFieldModel& model, double sigma_hit);
  // The table for scans of `range_max` (built on first use).
  const std::vector<float>& table(double range_max) const;
  // Whether the tables hold a value a cell (else a value a class).
  bool cellTables() const { return cell_tables_; }
  void buildTable(double range_max, std::vector<float>* out) const;
  void score(const float* table, const float* bx, const float* by, std::size_t beams,
             const ParticleSet& particles, std::vector<double>* log_likelihood) const;
  std::vector<uint8_t> keptBeams(const float* bx, const float* by, std::size_t beams,
                                 const ParticleSet& particles) const;

  LikelihoodFieldModelParams params_;
  std::shared_ptr<const DistanceField> field_;
  bool cell_tables_;
  // The precomputed tables, one per range_max: with cellTables(), (width +
  // 2) x (height + 2) with a border of "outside the map" cells; without, an
  // entry per class of the field's cells, then one for outside the map.
  mutable LikelihoodTables tables_;
  // For beam skipping: 1 where a cell lies within beam_skip_distance of an
  // obstacle, with the same border (0: outside the map agrees with nothing).
  std::vector<uint8_t> near_;
};

}  // namespace pf
