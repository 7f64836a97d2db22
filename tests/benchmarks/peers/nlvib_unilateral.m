% NLvib's harmonic balance of its own example 03 (two masses, unilateral
% spring of stiffness 100 at gap 1: EXAMPLES/03_twoDOFoscillator_unilateralSpring)
% at given points, run by tests/benchmarks/peers/unilateral_bench: NLvib's
% HB_residual (AFT on N samples, analytic Jacobian) solved by Octave's fsolve
% with the Jacobian from the start each line gives. One line per point:
%   Om median_seconds exitflag X   (X = [Q0; Qc1; Qs1; ...] over the two masses)
function nlvib_unilateral(nlvib_dir, points_file, H, N)
  addpath(fullfile(nlvib_dir, 'SRC'));
  addpath(fullfile(nlvib_dir, 'SRC', 'MechanicalSystems'));
  mi = [1 1]; ki = [0 1 1]; di = .03*ki; Fex1 = [0; .1];
  nl = struct('type', 'unilateralSpring', 'stiffness', 1e2, 'gap', 1, 'force_direction', [1; 0]);
  oscillator = ChainOfOscillators(mi, di, ki, nl, Fex1);
  opts = optimset('Jacobian', 'on', 'Display', 'off', 'TolFun', 1e-14, 'TolX', 1e-14, 'MaxIter', 100);
  P = load(points_file);
  for i = 1:size(P, 1)
    Om = P(i, 1); X0 = P(i, 2:end)';
    fun = @(X) residual(X, oscillator, H, N, Om);
    [X, ~, flag] = fsolve(fun, X0, opts);
    times = [];
    t_begin = tic;
    while numel(times) < 3 || (numel(times) < 15 && toc(t_begin) < 1)
      t0 = tic; fsolve(fun, X0, opts); times(end + 1) = toc(t0);
    end
    printf('%.17g %.6g %d', Om, median(times), flag);
    printf(' %.17g', X);
    printf('\n');
  end
end

function [R, J] = residual(X, oscillator, H, N, Om)
  [R, dR] = HB_residual([X; Om], oscillator, H, N, 'frf');
  J = dR(:, 1:end - 1);
end
