% NLvib's answer to the four bench problems (run by tests/benchmarks/peers/bench).
% The forced Duffing goes through NLvib's own HB_residual (SingleMassOscillator
% with a cubicSpring element, analytic Jacobian by AFT); NLvib has no element for
% sin(x) or (1 - x'^2)^(3/2), so the other three use residuals written the way
% NLvib's EXAMPLES/01_Duffing/HB_residual_Duffing.m is (AFT on N samples), with
% analytic Jacobians, frequency unknown and the two conditions at t = 0 for the
% autonomous ones. Every one is solved by Octave's fsolve with the Jacobian,
% tolerances at round-off. Prints one line per problem:
%   problem seconds Om a0 a1 b1 ... aH bH
function nlvib_bench(nlvib_dir, problems)
  addpath(fullfile(nlvib_dir, 'SRC'));
  addpath(fullfile(nlvib_dir, 'SRC', 'MechanicalSystems'));
  opts = optimset('Jacobian', 'on', 'Display', 'off', 'TolFun', 1e-15, 'TolX', 1e-15, 'MaxIter', 100);
  for i = 1:numel(problems)
    name = problems{i};
    switch name
      case 'duffing'
        H = 20; N = 4*H + 1; Om = 1.5;
        system = SingleMassOscillator(1, 0.1, 1, {struct('type', 'cubicSpring', 'stiffness', 1)}, 1);
        fun = @(X) duffing_residual(X, system, H, N, Om);
        x0 = zeros(2*H + 1, 1); x0(2) = 1.5;
        solve = @() fsolve(fun, x0, opts);
      case 'forced-pendulum'
        H = 20; N = 4*H + 1; Om = 0.8;
        fun = @(X) forced_pendulum_residual(X, H, N, Om);
        x0 = zeros(2*H + 1, 1); x0(2) = -2.2; x0(3) = 0.9;
        solve = @() fsolve(fun, x0, opts);
      case 'pendulum'
        H = 25; N = 4*H + 1; Om = NaN;
        fun = @(X) autonomous_residual(X, H, N, 'pendulum');
        x0 = [0; 1.5; zeros(2*H - 1, 1); 0.86];
        solve = @() fsolve(fun, x0, opts);
      case 'relativistic'
        H = 55; N = 4*H + 1; Om = NaN;
        fun = @(X) autonomous_residual(X, H, N, 'relativistic');
        x0 = zeros(2*H + 2, 1); x0(3) = 0.85/0.77; x0(end) = 0.77;
        solve = @() fsolve(fun, x0, opts);
      otherwise
        error(['unknown problem ' name]);
    end
    X = solve();
    times = [];
    t_begin = tic;
    while numel(times) < 3 || (numel(times) < 50 && toc(t_begin) < 2)
      t0 = tic; solve(); times(end + 1) = toc(t0);
    end
    if isnan(Om), Om = X(end); X = X(1:end - 1); end
    printf('%s %.17g %.17g', name, median(times), Om);
    printf(' %.17g', X);
    printf('\n');
  end
end

% Complex harmonics of real samples f (N x m) at 0..H, as NLvib does (fft / N).
function F = forward(f, H)
  N = size(f, 1);
  c = fft(f) / N;
  F = [real(c(1, :)); 2*real(c(2:H + 1, :)); -2*imag(c(2:H + 1, :))];
  % rows: a0, a1..aH, b1..bH -> interleave to a0 a1 b1 a2 b2 ...
  F = F([1, reshape([2:H + 1; H + 2:2*H + 1], 1, [])], :);
end

% E: N x (2H+1) synthesis, D: derivative in the sine-cosine layout (per unit Om).
function [E, D] = tables(H, N)
  tau = 2*pi*(0:N - 1)'/N;
  E = ones(N, 2*H + 1); D = zeros(2*H + 1);
  for k = 1:H
    E(:, 2*k) = cos(k*tau); E(:, 2*k + 1) = sin(k*tau);
    D(2*k + 1, 2*k) = -k; D(2*k, 2*k + 1) = k;  % d/dtau: a cos -> -k a sin, b sin -> k b cos
  end
end

function [R, J] = duffing_residual(Q, system, H, N, Om)
  [R, dR] = HB_residual([Q; Om], system, H, N, 'frf');
  J = dR(:, 1:end - 1);
end

% th'' + 0.1 th' + sin th = 0.5 cos(Om t), AFT with the exact Jacobian.
function [R, J] = forced_pendulum_residual(X, H, N, Om)
  persistent E D key
  if isempty(key) || ~isequal(key, [H N]), [E, D] = tables(H, N); key = [H N]; end
  L = Om^2*D*D + 0.1*Om*D;
  th = E*X;
  fex = zeros(2*H + 1, 1); fex(2) = 0.5;
  R = L*X + forward(sin(th), H) - fex;
  J = L + forward(cos(th).*E, H);
end

% pendulum th'' + sin th = 0, th(0) = 1.5, th'(0) = 0; relativistic
% x'' + (1 - x'^2)^(3/2) x = 0, x(0) = 0, x'(0) = 0.85. X = [coefficients; Om].
function [R, J] = autonomous_residual(X, H, N, which)
  persistent E D key
  if isempty(key) || ~isequal(key, [H N]), [E, D] = tables(H, N); key = [H N]; end
  Om = X(end); C = X(1:end - 1);
  x = E*C; v = Om*(E*(D*C)); a = Om^2*(E*(D*D*C));
  e0 = [1, ones(1, 2*H)]; e0(3:2:end) = 0;         % x(0) = a0 + sum a_k
  d0 = zeros(1, 2*H + 1); d0(3:2:end) = 1:H;       % x'(0)/Om = sum k b_k
  if strcmp(which, 'pendulum')
    g = a + sin(x);
    Jx = forward(cos(x).*E, H); Jv = zeros(2*H + 1);
    conditions = [e0*C - 1.5; Om*d0*C];
    Jc = [e0, 0; Om*d0, d0*C];
  else
    s = (1 - v.^2);
    g = a + s.^1.5.*x;
    Jx = forward(s.^1.5.*E, H);
    Jv = forward(-3*s.^0.5.*v.*x.*E, H);
    conditions = [e0*C; Om*d0*C - 0.85];
    Jc = [e0, 0; Om*d0, d0*C];
  end
  A = E*(D*D*C); B = E*(D*C);  % d a/d Om = 2 Om A, d v / d Om = B
  R = [forward(g, H); conditions];
  dOm = forward(2*Om*A, H);
  if ~strcmp(which, 'pendulum'), dOm = dOm + forward(-3*s.^0.5.*v.*x.*B, H); end
  J = [Om^2*D*D + Jx + Om*Jv*D, dOm; Jc];
end
