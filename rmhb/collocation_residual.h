#ifndef RMHB_COLLOCATION_RESIDUAL_H_
#define RMHB_COLLOCATION_RESIDUAL_H_

// The RHB equations (METHOD.md eq. 11) as a nonlinear problem:
//   E* g(t_j, z(t_j), z'(t_j)) = 0   for every equation g,
// z = E X sampled by an inverse FFT, projected back by a forward FFT, plus
// the point conditions. Unknowns: every variable's coefficients, then the
// unknown base frequencies. The analytic Jacobian uses the Toeplitz-plus-
// Hankel structure of E* diag(dg/dz) E, so its cost is O(K^2) per nonzero
// partial derivative instead of a dense M x K product.
//
// Half-turn symmetries (rmhb/symmetry.h) shrink the problem the solver sees:
// the residual is still evaluated on the full basis, but the unknowns and
// residual rows a symmetry forces to zero are left out of x, F and J.
//
// Condensation (optional): an equation c1 a' + c2 b = 0 (the recast's
// x' = v) defines b's coefficients as the linear map -c1/c2 D(w) A of a's.
// Those rows are exact, so b and its rows leave the problem and the chain
// rule folds b's Jacobian columns into a's and w's: half the unknowns of a
// second-order oscillator, about 8x less work in the dense factorisation.
// Symmetries then act on the condensed unknowns and rows (both halve).

#include <memory>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "rmhb/definition_check.h"
#include "rmhb/harmonic_balance_problem.h"
#include "rmhb/harmonic_basis.h"
#include "rmhb/nonlinear_solver.h"
#include "rmhb/point_condition.h"
#include "rmhb/polynomial_system.h"
#include "rmhb/sampling.h"
#include "rmhb/spectral_transform.h"
#include "rmhb/symmetry.h"

namespace rmhb {

class CollocationResidual : public NonlinearProblem {
 public:
  CollocationResidual(const HarmonicBalanceProblem& problem, const HarmonicBasis& basis,
                      const Sampling& sampling, bool condense_definitions = false);

  int num_unknowns() const override { return num_unknowns_; }
  int num_residuals() const override { return num_residuals_; }
  bool Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                Eigen::MatrixXd* jacobian) override;

  // Large problems (METHOD.md s.17). Linearize keeps, per equation and
  // slot, the partial derivative at the samples; J v is then one synthesis
  // per slot and one projection per equation, O(K log K) with FFTW, exact
  // (the same J as Evaluate's). SparseJacobian assembles J from the same
  // partials block by block: the (equation, variable) blocks that are
  // nonzero, each the Toeplitz-plus-Hankel block of its harmonics, those
  // beyond the first `coupling` fraction of harmonics by their 2 x 2
  // diagonal blocks only; the frequency columns are exact products.
  bool HasLinearization() const override { return true; }
  bool Linearize(const Eigen::VectorXd& x, Eigen::VectorXd* residual) override;
  void ApplyJacobian(const Eigen::VectorXd& v, Eigen::VectorXd* product) override;
  void SparseJacobian(double coupling, Eigen::SparseMatrix<double>* jacobian) override;
  // Nonzero (equation, variable) blocks over all blocks, after condensation.
  double JacobianDensity() const override { return density_; }

  // Between the solver's vector and [variable][coefficient] + frequencies;
  // Pack drops what the symmetries exclude, Unpack fills it with zeros.
  Eigen::VectorXd Pack(const Eigen::MatrixXd& coefficients,
                       const std::vector<double>& frequencies) const;
  void Unpack(const Eigen::VectorXd& x, Eigen::MatrixXd* coefficients,
              std::vector<double>* frequencies) const;
  // The linearisation about the solver's vector x split for Hill's method
  // (rmhb/hill_stability.h): a perturbation dz of the coefficients changes
  // the equations by value_part dz + derivative_part dz', where
  //   value_part      = E* diag(dg/dz) E,   derivative_part = E* diag(dg/dz') E,
  // square over the full coefficient unknowns (frequencies excluded), with the
  // constant row of every equation (balanced or not) so that the blocks stay
  // square. The solver's Jacobian is value_part + derivative_part D(w).
  void LinearizationParts(const Eigen::VectorXd& x, Eigen::MatrixXd* value_part,
                          Eigen::MatrixXd* derivative_part);
  // The same linearisation in the time domain, at the samples: for every
  // sample s, value(s, i n + v) = dg_i/dz_v and derivative(s, i n + v) =
  // dg_i/dz_v' (n variables, equations i < n, partials of every slot of a
  // variable summed). False (outputs untouched) when the system is not a
  // square system of first-order equations (a second derivative, more
  // equations than variables): rmhb/harmonic_monodromy.h integrates it.
  bool SampledPartials(const Eigen::VectorXd& x, Eigen::MatrixXd* value, Eigen::MatrixXd* derivative);
  // The same as sparse matrices, for Hill's method at large sizes: only
  // the (equation, variable) blocks that exist, each without the round-off
  // of its FFT (entries below 1e-14 of the block's largest: a constant
  // partial gives a diagonal block, not a dense one).
  void LinearizationParts(const Eigen::VectorXd& x, Eigen::SparseMatrix<double>* value_part,
                          Eigen::SparseMatrix<double>* derivative_part);
  // Unknowns and residuals before the symmetry reduction.
  int num_full_unknowns() const { return full_unknowns_; }
  int num_full_residuals() const { return full_residuals_; }
  // Variables eliminated by condensation (0 when off or nothing matched).
  int num_condensed_variables() const { return num_condensed_; }
  // True when Evaluate goes through the sampled maps below (small problem of
  // known frequencies); the general path otherwise. For tests and reports.
  bool uses_sampled_maps() const { return sampled_maps_eligible_; }
  void DisableSampledMaps() { sampled_maps_eligible_ = false; }

 private:
  struct CompiledTerm {
    double coefficient;
    int time;  // index into time_samples_, -1 for 1
    std::vector<std::pair<int, int>> factors;  // (slot index, power)
  };
  struct CompiledEquation {
    std::vector<CompiledTerm> terms;
    std::vector<int> slots;  // slots appearing in the equation
    int first_row;           // in the residual vector
    bool balance_constant;
    // Pointwise equations (PolynomialSystem::AddPointwiseEquation): the
    // evaluator, and where its values live in pointwise_values_.
    const PointwiseEquation* pointwise = nullptr;
    int pointwise_index = -1;
  };
  struct SlotInfo {
    int variable;
    int derivative;
  };

  void Frequencies(const Eigen::VectorXd& x, std::vector<double>* w) const;
  // The linearisation's blocks at x, one (equation, slot) at a time.
  template <typename AddBlock>
  void ForEachBlock(const Eigen::VectorXd& x, AddBlock add);
  // The residual on the full, unreduced rows; the Jacobian on the kept rows
  // and unknowns (all of them when there is no symmetry): a reduced J is
  // assembled in place, never as the full one cut down (at N = 55 that was
  // a 100 KB matrix cleared per evaluation for 29 x 29 kept entries).
  bool EvaluateFull(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                    Eigen::MatrixXd* jacobian);
  void SetUpSymmetries();
  // row_harmonics_, column_harmonics_ from the kept rows and columns.
  void SetUpKeptHarmonics();
  void SetUpCondensation();
  // Condensed unknowns -> the full layout (defined variables computed).
  void Expand(const Eigen::VectorXd& x, Eigen::VectorXd* full) const;
  // J(full rows row.., full column) += factor * values[0 .. count): into
  // the kept rows and column only when symmetries reduce J.
  void AddToColumn(Eigen::MatrixXd* jacobian, int column, int row, int count, double factor,
                   const double* values) const;
  // J(row.., columns of variable j) += block (rows x C_), with the chain rule
  // through a definition when j was condensed away; X is the full layout.
  void AddVariableBlock(Eigen::MatrixXd* jacobian, int row,
                        const Eigen::Ref<const Eigen::MatrixXd>& block, int j,
                        const Eigen::VectorXd& X) const;
  // Where coefficient c of variable j lands among the (condensed) unknowns
  // and with which factor: itself, or through the definition j = ratio
  // D(w) source (rates: the basis frequencies at w). False when nothing
  // depends on it (a defined variable's mean).
  bool ChainColumn(int j, int c, const std::vector<double>& rates, int* column, double* factor) const;
  // Where the partial of a slot of variable j lands in the reduced J: its
  // kept columns (SpectralTransform::Targets, rows left unset), or for a
  // condensed variable v = ratio D(w) A its source A's (ChainColumn).
  void ColumnTargets(int j, SpectralTransform::Targets* targets);
  // A slot's partial (samples in work_) of equation i straight into the
  // reduced J (METHOD.md s.13): false where only the C x C block serves
  // (several grid angles; a condensed variable's derivative under a partial
  // that is not constant).
  bool AddSlotDirectly(size_t i, int s, bool constant, const Eigen::VectorXd& x, Eigen::MatrixXd* jacobian);
  // Slot (i, variable j)'s frequency columns: d/dw_b of ratio D(w) A (and
  // D(rates) of it when `derivative`), through equation i's partial in
  // work_, by one synthesis and projection per unknown frequency. A
  // derivative slot's own z' = D(w) z is ratio 1 and A = z; a condensed
  // variable's definition v = ratio D(w) A adds its own (METHOD.md s.13).
  void AddFrequencyColumns(size_t i, int j, const double* A, double ratio, bool derivative,
                           Eigen::MatrixXd* jacobian);
  void AddSlotThroughBlock(int i, int s, const double* rates, bool constant, const Eigen::VectorXd& x,
                           Eigen::MatrixXd* jacobian);
  // Sparse J: block (block row i -> full residual row rows_of(i) or -1,
  // block column l -> coefficient first + l of variable j) into triplets,
  // through the chain rule, in the reduced indices.
  template <class RowsOf>
  void AddSparseBlock(std::vector<Eigen::Triplet<double>>* triplets, RowsOf rows_of, int first,
                      const Eigen::Ref<const Eigen::MatrixXd>& block, int j) const;
  // z(0) and z'(0) of every variable of the layout X at the rates given.
  void PointValues(const Eigen::VectorXd& X, const std::vector<double>& rates, Eigen::VectorXd* z,
                   Eigen::VectorXd* dz) const;
  void SetUpLinearAlgebra();
  // Small problems of known frequencies (METHOD.md s.21): with w fixed, the
  // samples of every slot are a linear map A_s of the solver's x (layout,
  // symmetries, condensation and derivative rates folded in), and the rows
  // of equation i a linear map Q_i of its samples. F = sum_i Q_i g_i(A x) and
  // J = sum_i Q_i sum_s diag(dg_i/dz_s) A_s are then a few small dense
  // products, with none of the general path's per-column bookkeeping: at the
  // Monte Carlo's 7 unknowns that bookkeeping was most of an evaluation.
  // The maps are built by passing unit vectors through the general path's
  // own steps, so both paths are the same linear algebra, and rebuilt when
  // the problem's frequencies change (continuation in w retunes them).
  void BuildSampledMaps();
  // The affine part of every equation as L_i, b_i; the nonlinear terms and
  // their slots (maps_.nonlinear, maps_.nonlinear_slots).
  void BuildAffineMaps();
  bool EvaluateSampled(const Eigen::VectorXd& x, Eigen::VectorXd* residual, Eigen::MatrixXd* jacobian);
  // The slot samples' highest power is finite (every sample below
  // overflow_bound_): an admissible point for either path.
  bool SamplesAdmissible() const;
  // proj_ = the rows of equation i (C_ entries, zeros where a symmetry drops
  // a harmonic) from its samples.
  void ProjectEquation(size_t i, const double* samples);
  int FrequencyColumn(int base) const { return frequency_column_ + unknown_index_[base]; }
  // The reduced vector on the full unknowns (x itself without symmetries):
  // the condensed layout when condensing.
  const Eigen::VectorXd& Full(const Eigen::VectorXd& x);
  // The solver's vector in the layout EvaluateFull reads (symmetries
  // undone, condensed variables computed).
  const Eigen::VectorXd& Layout(const Eigen::VectorXd& x);
  // samples = E coefficients for variable j's coefficients (or values derived
  // from them), only the kept ones under a symmetry.
  void SynthesizeVariable(int j, const double* coefficients, double* samples);
  // Samples of every slot, z_j = E X_j and z_j' = E D(w) X_j, for full x.
  void SampleSlots(const Eigen::VectorXd& x);
  // p = sum over terms of d(term)/d(slot), or the whole equation if slot < 0.
  void EvaluateSamples(const CompiledEquation& eq, int slot, double* out) const;
  // Every pointwise equation and its partials at every sample (after
  // SampleSlots), into pointwise_values_.
  void EvaluatePointwise(const std::vector<double>& w);

  const HarmonicBalanceProblem& problem_;
  HarmonicBasis basis_;
  std::unique_ptr<SpectralTransform> transform_;
  int n_;  // variables
  int degree_ = 1;  // of the polynomial equations, at least 1 (overflow test)
  int C_;  // coefficients per variable
  long M_;
  int num_unknowns_;
  int num_residuals_;
  int full_unknowns_;
  int full_residuals_;
  // Reduced index -> full index; empty when there is no symmetry.
  std::vector<int> kept_unknowns_, kept_residuals_;
  Eigen::VectorXd full_x_, full_residual_;
  std::vector<int> unknown_index_;  // base -> unknown slot or -1
  // z_j = ratio * z_source' when condensed away (source >= 0).
  struct Definition {
    int source = -1;
    double ratio = 0;
  };
  std::vector<Definition> definitions_;
  std::vector<int> column_;  // first Jacobian column of each variable, -1 if condensed
  int frequency_column_ = 0;
  int layout_size_ = 0;  // n_ C_ + unknown frequencies: the full layout
  int num_condensed_ = 0;
  Eigen::VectorXd expanded_;
  std::vector<SlotInfo> slots_;
  std::vector<CompiledEquation> equations_;
  std::vector<Eigen::VectorXd> time_samples_;
  // Work buffers, reused across evaluations (no allocation in the loop).
  std::vector<Eigen::VectorXd> slot_samples_;
  Eigen::VectorXd work_, term_, proj_, coef_;
  Eigen::MatrixXd block_;  // C x C, sized on first use: Newton-Krylov never forms it
  // Per equation: coefficient row -> row of the reduced J (-1: dropped);
  // one variable's columns at a time (ColumnTargets).
  std::vector<std::vector<int>> row_targets_;
  std::vector<int> column_target_;
  std::vector<double> rates_;
  std::vector<double> chain_rates_;  // ratio * rates_ of a condensed variable (ColumnTargets)
  // Per pointwise equation: samples x (value, d/d(slot) per slot of eq.slots).
  std::vector<Eigen::MatrixXd> pointwise_values_;
  std::vector<double> pointwise_in_, pointwise_out_;
  Eigen::MatrixXd pointwise_many_in_;  // samples x (t, slots, frequencies)
  std::vector<double> sample_phase_;  // 2 pi s / M of base 1, per sample
  // Kept by Linearize: the layout X, the rates at its frequencies, the
  // partials [equation][slot of eq.slots] at the samples, the point
  // conditions' gradients at t = 0.
  struct Linearization {
    Eigen::VectorXd X;
    std::vector<double> rates;
    std::vector<std::vector<Eigen::VectorXd>> partials;
    std::vector<Eigen::VectorXd> gz, gdz;
  };
  Linearization linearization_;
  std::vector<Eigen::VectorXd> tangent_samples_;
  Eigen::VectorXd tangent_residual_;
  // Full index -> reduced index, -1 where a symmetry drops it.
  std::vector<int> reduced_row_, reduced_column_;
  // Under a symmetry, per equation (rows) and per variable (columns): 1 where
  // the reduced Jacobian keeps a coefficient of that harmonic. The dense
  // Jacobian is assembled only there; empty without symmetries.
  std::vector<std::vector<char>> row_harmonics_, column_harmonics_;
  // The same as coefficient indices (0 .. C_ - 1), for the transforms.
  std::vector<std::vector<int>> row_coefficients_, column_coefficients_;
  double density_ = 1;
  // Beyond it a sample's highest power overflows: not an admissible point.
  double overflow_bound_ = 0;
  bool sampled_maps_eligible_ = false;
  struct SampledMaps {
    std::vector<double> frequencies;        // the maps hold at these
    std::vector<Eigen::MatrixXd> slot;      // A_s: M x num_unknowns
    // The slots of nonlinear terms, their A_s stacked (the k-th in rows
    // k M .. k M + M - 1): their samples in one product, and its result.
    std::vector<int> nonlinear_slots;
    Eigen::MatrixXd stacked;
    Eigen::VectorXd stacked_samples;
    // Q_i: equation i's rows (reduced, contiguous from equation_row[i]) x M;
    // empty when condensed away.
    std::vector<Eigen::MatrixXd> equation;
    std::vector<int> equation_row;
    // Equation i's terms of degree <= 1 are affine in x: their rows are
    // linear[i] x + constant[i], made once; nonlinear[i] keeps the others.
    std::vector<Eigen::MatrixXd> linear;
    std::vector<Eigen::VectorXd> constant;
    std::vector<CompiledEquation> nonlinear;
    // outer[i][k]: column t holds Q_i(:, t) A_s(t, :) for the k-th slot s of
    // nonlinear[i], flattened column-major (rows x num_unknowns): the
    // nonlinear part of J_i is then sum_k outer[i][k] dg_i/dz_s, one
    // matrix-vector product per slot.
    std::vector<std::vector<Eigen::MatrixXd>> outer;
    Eigen::VectorXd flat;                   // work: that sum
    Eigen::MatrixXd weighted;               // work: sum_s diag(dg_i/dz_s) A_s (set-up)
  };
  SampledMaps maps_;
};

}  // namespace rmhb

#endif  // RMHB_COLLOCATION_RESIDUAL_H_
