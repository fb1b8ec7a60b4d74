"""Which stimulus is it? Classification of array readings under offsets and noise.

Readings of each stimulus (class) are taken at random sub-pitch offsets of the stimulus
relative to the array (uniform over one lattice cell) and passed through the readout (noise,
quantisation). Two rules:

- "template": nearest template (Euclidean) among the noise-free readings of every class at a
  `template_grid` x `template_grid` lattice of offsets over the cell: a matched filter that
  knows the stimuli but not their position.
- "lda": scikit-learn's LinearDiscriminantAnalysis (shrinkage chosen by Ledoit-Wolf, which
  stays well posed with more taxels than training readings), trained on an independent
  draw of offsets and noise.

Accuracy is over a test draw independent of both; confusion[i, j] counts class i read as j.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from tactileskin.array.maps import interpolator
from tactileskin.array.sampler import ArraySpec, Readout, sample
from tactileskin.errors import ParameterError

METHODS = ("template", "lda")
# The readings and classifiers of one (set, pitch) are held in memory at once (chart.compute):
# the clean readings, their noisy copies, the template distances and LDA's taxel covariance,
# n_taxels^2 floats in a few copies while it is shrunk and solved (1.57 GB peak measured at
# 81 x 81 taxels, 0.34 GB a copy). A chart that would need more is refused before any solve
# (ChartConfig): at 161 x 161 taxels the covariance alone is 5 GB a copy.
MAX_BYTES = 4 * 2**30
LDA_COPIES = 5


def memory_bytes(n_class: int, n_taxels: int, n_train: int, n_test: int, template_grid: int) -> float:
    """Estimated peak bytes of classifying one (set, pitch): `n_class` stimuli read by
    `n_taxels` taxels at n_train + n_test random offsets and template_grid^2 template ones."""
    g2 = float(template_grid) ** 2
    readings = n_class * (2.0 * (n_train + n_test) + g2) * n_taxels * 8.0  # clean + noisy
    distances = float(n_class) * n_test * n_class * g2 * 8.0               # nearest template
    return readings + distances + LDA_COPIES * float(n_taxels) ** 2 * 8.0


@dataclass
class Evaluation:
    labels: list
    accuracy: dict          # method -> fraction correct
    confusion: dict         # method -> (n, n) counts, rows true, columns read
    n_test: int             # test readings per class
    # method -> (n_test,) fraction of the classes read right at each test offset (the offsets
    # are shared by all classes: the clusters of chart.accuracy_interval)
    offset_accuracy: dict = dataclasses.field(default_factory=dict)

    @property
    def chance(self) -> float:
        return 1.0 / len(self.labels)


def random_offsets(spec: ArraySpec, n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 2) offsets uniform over one lattice cell [-pitch/2, pitch/2)^2."""
    return rng.uniform(-0.5 * spec.pitch, 0.5 * spec.pitch, size=(n, 2))


def grid_offsets(spec: ArraySpec, g: int) -> np.ndarray:
    """(g*g, 2) offsets at the centres of a g x g subdivision of the lattice cell."""
    k = ((np.arange(g) + 0.5) / g - 0.5) * spec.pitch
    S, Z = np.meshgrid(k, k)
    return np.column_stack([S.ravel(), Z.ravel()])


def readings(maps: dict, spec: ArraySpec, offsets: np.ndarray) -> np.ndarray:
    """Noise-free readings (n_class, n_offsets, n_taxels) of each map (in dict order)."""
    out = []
    for m in maps.values():
        f = interpolator(m)
        out.append(np.stack([sample(m, spec, o, f) for o in offsets]))
    return np.stack(out)


def nearest_template(templates: np.ndarray, template_labels: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Label of the nearest template (rows of `templates`) for each row of X."""
    d2 = (np.einsum("ij,ij->i", X, X)[:, None] - 2.0 * X @ templates.T
          + np.einsum("ij,ij->i", templates, templates)[None, :])
    return np.asarray(template_labels)[np.argmin(d2, axis=1)]


def _lda():
    from sklearn.discriminant_analysis import LinearDiscriminantAnalysis

    return LinearDiscriminantAnalysis(solver="lsqr", shrinkage="auto")


def classify(train: np.ndarray, test: np.ndarray, templates: np.ndarray, methods=METHODS) -> dict:
    """Predictions per method for readings shaped (n_class, n_draws, n_taxels); returns
    {method: predicted labels (n_class, n_test)}."""
    ncls = test.shape[0]
    y_train = np.repeat(np.arange(ncls), train.shape[1])
    X_test = test.reshape(-1, test.shape[2])
    out = {}
    for m in methods:
        if m == "template":
            lab = np.repeat(np.arange(ncls), templates.shape[1])
            pred = nearest_template(templates.reshape(-1, templates.shape[2]), lab, X_test)
        elif m == "lda":
            pred = _lda().fit(train.reshape(-1, train.shape[2]), y_train).predict(X_test)
        else:
            raise ParameterError("method", m, " or ".join(METHODS))
        out[m] = pred.reshape(ncls, -1)
    return out


def score(pred: dict, labels) -> tuple[dict, dict]:
    """(accuracy, confusion) per method from predictions (n_class, n_test)."""
    from sklearn.metrics import confusion_matrix

    n = len(labels)
    acc, conf = {}, {}
    for m, p in pred.items():
        truth = np.repeat(np.arange(n), p.shape[1])
        acc[m] = float(np.mean(p.ravel() == truth))
        conf[m] = confusion_matrix(truth, p.ravel(), labels=np.arange(n))
    return acc, conf


def offset_scores(pred: dict) -> dict:
    """{method: (n_test,) fraction of the classes read right at each test offset}."""
    return {m: np.mean(p == np.arange(p.shape[0])[:, None], axis=0) for m, p in pred.items()}


def evaluate(maps: dict, spec: ArraySpec, readout: Readout, rng: np.random.Generator, *,
             n_train: int = 24, n_test: int = 24, template_grid: int = 4, methods=METHODS,
             clean: dict | None = None) -> Evaluation:
    """Accuracy and confusion of the stimuli `maps` {name: BoneMap} read by `spec` + `readout`.
    `clean` may carry precomputed noise-free readings {"train", "test", "templates"} (they do
    not depend on the readout), as `clean_readings` returns."""
    if len(maps) < 2:
        raise ParameterError("stimuli", len(maps), "at least two stimuli to tell apart")
    clean = clean or clean_readings(maps, spec, rng, n_train=n_train, n_test=n_test, template_grid=template_grid)
    train = readout(clean["train"], rng)
    test = readout(clean["test"], rng)
    pred = classify(train, test, clean["templates"], methods)
    acc, conf = score(pred, list(maps))
    return Evaluation(list(maps), acc, conf, test.shape[1], offset_scores(pred))


def clean_readings(maps: dict, spec: ArraySpec, rng: np.random.Generator, *, n_train: int = 24,
                   n_test: int = 24, template_grid: int = 4) -> dict:
    """Noise-free readings at random train and test offsets and at the template offsets."""
    for name, v in (("n_train", n_train), ("n_test", n_test), ("template_grid", template_grid)):
        if not (isinstance(v, (int, np.integer)) and v >= 1):
            raise ParameterError(name, v, "an integer >= 1")
    return {"train": readings(maps, spec, random_offsets(spec, n_train, rng)),
            "test": readings(maps, spec, random_offsets(spec, n_test, rng)),
            "templates": readings(maps, spec, grid_offsets(spec, template_grid))}
