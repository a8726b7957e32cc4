"""Gaussian-process models in numpy/scipy: shared GPLVM with GPDM dynamics, GP regression.

Notation: ``K = var * exp(-gamma/2 |x - x'|²) + noise * I`` (RBF + white) for the
output mappings; the GPDM dynamics kernel adds a linear term,
``k_X(x, x') = a1 exp(-a2/2 |x - x'|²) + a3 x.x' + a4 δ``.
The negative log likelihood of outputs ``Y`` (N x D, centred) under a kernel
matrix ``K`` is ``D/2 log|K| + 1/2 tr(K^-1 Y Y^T)`` (+ const), with
``dL/dK = 1/2 (D K^-1 - K^-1 Y Y^T K^-1)``; gradients with respect to the
latent points and the log hyperparameters follow by the chain rule (see
:func:`_rbf_grads`). All hyperparameters are optimised in log space with the
GPDM ``1/θ`` priors (adding ``log θ``) on kernel variances and inverse widths.

:class:`SharedGPDM` is the model of the hybrid mesh paper: several output
spaces (``Y_S`` skeleton, ``Y_M`` mesh detail) share one latent space ``X``
whose trajectory is governed by GPDM dynamics; the objective is the negative
log of the product of the shared-GPLVM likelihoods and the GPDM latent
likelihood, minimised by L-BFGS-B with analytic gradients.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy import linalg, optimize
from threadpoolctl import threadpool_limits

log = logging.getLogger("animsynth.meshdetail.gp")

LOG_BOUNDS_OUT = [(-6.0, 6.0), (-8.0, 6.0), (np.log(1e-5), np.log(10.0))]  # var, gamma, noise
LOG_BOUNDS_DYN = [(-6.0, 6.0), (-8.0, 6.0), (-8.0, 4.0), (np.log(1e-5), np.log(10.0))]  # a1..a4


def sqdist(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    aa = np.sum(A * A, axis=1)[:, None]
    bb = np.sum(B * B, axis=1)[None, :]
    return np.maximum(aa + bb - 2.0 * A @ B.T, 0.0)


def rbf(A, B, var, gamma):
    return var * np.exp(-0.5 * gamma * sqdist(A, B))


def gp_nll(K: np.ndarray, YYt: np.ndarray, D: int):
    """Negative log likelihood ``D/2 log|K| + 1/2 tr(K^-1 YY^T)`` and ``dL/dK``.

    Returns (nll, G, Kinv). Raises ``np.linalg.LinAlgError`` if K is not positive definite.
    """
    N = K.shape[0]
    c = linalg.cho_factor(K, lower=True, check_finite=False)
    Kinv = linalg.cho_solve(c, np.eye(N), check_finite=False)
    logdet = 2.0 * np.sum(np.log(np.diag(c[0])))
    KiY = Kinv @ YYt
    nll = 0.5 * D * logdet + 0.5 * np.trace(KiY) + 0.5 * N * D * np.log(2 * np.pi)
    G = 0.5 * (D * Kinv - KiY @ Kinv)
    G = 0.5 * (G + G.T)
    return nll, G, Kinv


def _rbf_grads(G, X, Krbf, gamma, r2):
    """Gradients of sum(G * Krbf) w.r.t. X, log var, log gamma (G symmetric)."""
    A = G * Krbf
    dX = -2.0 * gamma * (A.sum(axis=1)[:, None] * X - A @ X)
    dlv = np.sum(A)
    dlg = np.sum(A * (-0.5 * gamma * r2))
    return dX, dlv, dlg


def pca_init(Y: np.ndarray, q: int) -> np.ndarray:
    Yc = Y - Y.mean(axis=0)
    U, s, _ = np.linalg.svd(Yc, full_matrices=False)
    X = U[:, :q] * s[:q]
    if X.shape[1] < q:
        X = np.concatenate([X, np.zeros((len(X), q - X.shape[1]))], axis=1)
    sd = X[:, 0].std()
    return X / (sd if sd > 0 else 1.0)


class _Normaliser:
    """Centre each column, divide a whole block by one scale (keeps relative variances)."""

    def fit(self, Y):
        self.mean_ = Y.mean(axis=0)
        sd = np.sqrt(np.mean((Y - self.mean_) ** 2))
        self.scale_ = sd if sd > 0 else 1.0
        return self

    def transform(self, Y):
        return (Y - self.mean_) / self.scale_

    def inverse(self, Z):
        return Z * self.scale_ + self.mean_


class SharedGPDM:
    """Shared GPLVM (one RBF mapping per output space) with GPDM latent dynamics.

    Parameters
    ----------
    latent_dim : int
        Dimension of the shared latent space X (paper: 4).
    iterations : int
        L-BFGS-B iterations (paper: 100).
    dynamics : bool
        Include the GPDM dynamics term (False = plain shared GPLVM).
    dynamics_weight : float
        Multiplier of the GPDM term (1 = the plain product of likelihoods).
    init : {"pca0", "pca_all"}
        Initialise X from the PCA of the first output space (paper: Y_S) or of all of them.

    Attributes
    ----------
    X_ : (N, q) latent points; hyper_ : list of (var, gamma, noise) per output;
    dyn_hyper_ : (a1, a2, a3, a4); nll_ : final objective; n_evals_ : objective evaluations.
    """

    def __init__(self, latent_dim: int = 4, iterations: int = 100, dynamics: bool = True,
                 dynamics_weight: float = 1.0, init: str = "pca0"):
        self.latent_dim = int(latent_dim)
        self.iterations = int(iterations)
        self.dynamics = bool(dynamics)
        self.dynamics_weight = float(dynamics_weight)
        self.init = init

    # -- parameter packing -------------------------------------------------
    def _unpack(self, theta):
        N, q, M = self._N, self.latent_dim, self._M
        X = theta[: N * q].reshape(N, q)
        k = N * q
        hyp = [np.exp(theta[k + 3 * m: k + 3 * m + 3]) for m in range(M)]
        dyn = np.exp(theta[k + 3 * M: k + 3 * M + 4])
        return X, hyp, dyn

    def objective(self, theta):
        """Negative log posterior and its gradient (the function L-BFGS minimises)."""
        X, hyp, dyn = self._unpack(theta)
        N, q = X.shape
        grad = np.zeros_like(theta)
        gX = np.zeros_like(X)
        f = 0.0
        r2 = sqdist(X, X)
        k0 = N * q
        for m, (YYt, D) in enumerate(zip(self._YYt, self._D)):
            var, gamma, noise = hyp[m]
            Kr = var * np.exp(-0.5 * gamma * r2)
            K = Kr + (noise + 1e-8) * np.eye(N)
            nll, G, _ = gp_nll(K, YYt, D)
            dX, dlv, dlg = _rbf_grads(G, X, Kr, gamma, r2)
            gX += dX
            f += nll + np.log(var) + np.log(gamma)  # 1/theta priors
            grad[k0 + 3 * m: k0 + 3 * m + 3] = [dlv + 1.0, dlg + 1.0, noise * np.trace(G)]
        kd = k0 + 3 * self._M
        if self.dynamics and N > 2:
            a1, a2, a3, a4 = dyn
            w = self.dynamics_weight
            Xin, Xout = X[:-1], X[1:]
            r2d = r2[:-1, :-1]
            Kr = a1 * np.exp(-0.5 * a2 * r2d)
            Kl = a3 * (Xin @ Xin.T)
            K = Kr + Kl + (a4 + 1e-8) * np.eye(N - 1)
            nll, G, Kinv = gp_nll(K, Xout @ Xout.T, q)
            dXin, dla1, dla2 = _rbf_grads(G, Xin, Kr, a2, r2d)
            dXin += 2.0 * a3 * (G @ Xin)
            dXout = Kinv @ Xout
            f += w * (nll + 0.5 * np.sum(X[0] ** 2)) + np.log(a1) + np.log(a2) + np.log(a3)
            gX[:-1] += w * dXin
            gX[1:] += w * dXout
            gX[0] += w * X[0]
            grad[kd: kd + 4] = [w * dla1 + 1.0, w * dla2 + 1.0, w * np.sum(G * Kl) + 1.0, w * a4 * np.trace(G)]
        grad[:k0] = gX.ravel()
        return f, grad

    def fit(self, Ys: list[np.ndarray]) -> "SharedGPDM":
        """Fit to output spaces ``Ys`` (each N x D_m, rows = consecutive frames of one sequence)."""
        Ys = [np.asarray(Y, float) for Y in Ys]
        N = Ys[0].shape[0]
        if any(Y.shape[0] != N for Y in Ys):
            raise ValueError("all output spaces need the same number of frames")
        if N < self.latent_dim + 2:
            raise ValueError(f"need at least {self.latent_dim + 2} frames, got {N}")
        for Y in Ys:
            if not np.all(np.isfinite(Y)):
                raise ValueError("training outputs contain non-finite values")
        self.norm_ = [_Normaliser().fit(Y) for Y in Ys]
        Z = [n.transform(Y) for n, Y in zip(self.norm_, Ys)]
        self._N, self._M = N, len(Ys)
        self._YYt = [z @ z.T for z in Z]
        self._D = [z.shape[1] for z in Z]
        X0 = pca_init(Z[0] if self.init == "pca0" else np.concatenate(Z, axis=1), self.latent_dim)
        theta0 = np.concatenate([X0.ravel()] + [np.log([1.0, 1.0, 0.01])] * self._M + [np.log([1.0, 1.0, 0.1, 0.01])])
        bounds = [(None, None)] * X0.size + LOG_BOUNDS_OUT * self._M + LOG_BOUNDS_DYN
        self.n_evals_ = 0

        def fun(th):
            self.n_evals_ += 1
            try:
                return self.objective(th)
            except np.linalg.LinAlgError:
                return 1e25, np.zeros_like(th)

        # small dense matrices: one BLAS thread is much faster (and immune to oversubscription)
        with threadpool_limits(limits=1, user_api="blas"):
            res = optimize.minimize(fun, theta0, jac=True, method="L-BFGS-B", bounds=bounds,
                                    options={"maxiter": self.iterations, "maxfun": 3 * self.iterations + 20})
        self.X_, hyp, dyn = self._unpack(res.x)
        self.hyper_ = [tuple(h) for h in hyp]
        self.dyn_hyper_ = tuple(dyn)
        self.nll_ = float(res.fun)
        self.n_iter_ = int(res.nit)
        self.alpha_ = []
        for m, z in enumerate(Z):
            var, gamma, noise = self.hyper_[m]
            K = rbf(self.X_, self.X_, var, gamma) + (noise + 1e-8) * np.eye(N)
            self.alpha_.append(linalg.cho_solve(linalg.cho_factor(K, lower=True), z))
        del self._YYt
        log.info("SharedGPDM: %d iterations, %d evaluations, nll %.2f", self.n_iter_, self.n_evals_, self.nll_)
        return self

    def predict(self, Xs: np.ndarray, output: int) -> np.ndarray:
        """Posterior mean of output space ``output`` at latent points ``Xs`` (de-normalised)."""
        var, gamma, _ = self.hyper_[output]
        return self.norm_[output].inverse(rbf(np.atleast_2d(Xs), self.X_, var, gamma) @ self.alpha_[output])


class GPRegression:
    """GP regression with an RBF + white kernel; hyperparameters by maximum marginal likelihood.

    Used for the inverse mapping ``f_S^-1 : y_S -> x``. Inputs are normalised
    with one scale, outputs centred and scaled.

    Parameters
    ----------
    iterations : int
        L-BFGS-B iterations for the three log hyperparameters (analytic gradients).
    """

    def __init__(self, iterations: int = 100):
        self.iterations = int(iterations)

    def objective(self, logh, Xin, YYt, D):
        var, gamma, noise = np.exp(logh)
        r2 = sqdist(Xin, Xin)
        Kr = var * np.exp(-0.5 * gamma * r2)
        K = Kr + (noise + 1e-8) * np.eye(len(Xin))
        nll, G, _ = gp_nll(K, YYt, D)
        A = G * Kr
        g = np.array([np.sum(A) + 1.0, np.sum(A * (-0.5 * gamma * r2)) + 1.0, noise * np.trace(G)])
        return nll + np.log(var) + np.log(gamma), g

    def fit(self, Xin: np.ndarray, Y: np.ndarray) -> "GPRegression":
        Xin = np.asarray(Xin, float)
        Y = np.asarray(Y, float)
        self.xnorm_ = _Normaliser().fit(Xin)
        self.ynorm_ = _Normaliser().fit(Y)
        Xn, Yn = self.xnorm_.transform(Xin), self.ynorm_.transform(Y)
        YYt = Yn @ Yn.T
        D = Yn.shape[1]
        # initial inverse width from the median pairwise distance
        med = np.median(sqdist(Xn, Xn)[np.triu_indices(len(Xn), 1)]) if len(Xn) > 1 else 1.0
        h0 = np.log([1.0, 1.0 / max(med, 1e-6), 1e-2])

        def fun(h):
            try:
                return self.objective(h, Xn, YYt, D)
            except np.linalg.LinAlgError:
                return 1e25, np.zeros(3)

        with threadpool_limits(limits=1, user_api="blas"):
            res = optimize.minimize(fun, h0, jac=True, method="L-BFGS-B", bounds=LOG_BOUNDS_OUT,
                                    options={"maxiter": self.iterations})
        self.hyper_ = tuple(np.exp(res.x))
        var, gamma, noise = self.hyper_
        self.Xtrain_ = Xn
        K = rbf(Xn, Xn, var, gamma) + (noise + 1e-8) * np.eye(len(Xn))
        self.alpha_ = linalg.cho_solve(linalg.cho_factor(K, lower=True), Yn)
        return self

    def predict(self, Xs: np.ndarray) -> np.ndarray:
        var, gamma, _ = self.hyper_
        Xs = self.xnorm_.transform(np.atleast_2d(np.asarray(Xs, float)))
        return self.ynorm_.inverse(rbf(Xs, self.Xtrain_, var, gamma) @ self.alpha_)
