"""Tuning a law with Optuna over the in-process core (`testbed tune`).

Every law gets the same search: its space comes from the parameter table
(`testbed.search_space(law)`, declared beside each key in
controller/src/params.rs), its budget is the same `--trials N`, its
objective the same median IAE after T_c over the same training seeds, a
run that leaves the envelope after T_c or fails counting as the worst
value. The sampler is Optuna's TPE, seeded; a median pruner stops a trial
whose running median is worse than the median of earlier trials at the
same number of seeds. Studies live in an Optuna JournalStorage file, which
several processes (or Slurm array tasks on a shared file system) may share;
a study killed at any point resumes with every trial recorded once.

    python -m testbed.tune run --law nac --scenario paper_randomised --trials 200
    python -m testbed.tune report studies/nac-paper_randomised.journal
    python -m testbed.tune best studies/nac-paper_randomised.journal --write-scenario nac_best.toml
    python -m testbed.tune evaluate studies/*.journal --seeds 20 --first-seed 10000

docs/tuning.md has the whole interface and what the objective means.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import socket
import statistics
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from . import _native

#: The objective of a study whose trial could not be scored at all (its
#: median run left the envelope or failed): worse than any IAE.
WORST = 1e9

#: The ablation a learning study measures the networks against.
NO_NETWORKS = "nac-no-networks"


def _optuna():
    try:
        import optuna
    except ImportError as e:  # the `tune` extra
        raise SystemExit(
            "testbed tune needs Optuna: pip install 'optuna>=4' (or the wheel's `tune` extra)"
        ) from e
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna


@dataclass
class Setup:
    """What a study searches, on what, for how long: stored in the study, so
    that every process that shares it runs the same search, and a resumed
    study is the study it was."""

    law: str
    scenario: str
    robot: str | None = None
    trials: int = 200
    seeds: int = 8
    first_seed: int = 1000
    duration: float | None = 4.0
    #: "iae" (the law's own error) or "learning" (nac's IAE minus
    #: nac-no-networks' at the same knobs: what the networks contribute).
    objective: str = "iae"
    #: "all" (the law's space) or "learning" (the actor's and critic's knobs only).
    space: str = "all"
    #: Keys held at a value (`controller.k1=3.75`), beside the scenario's.
    fixed: dict = field(default_factory=dict)
    #: Multiplies the scenario's K1 and K2 before anything else (0.25: a quarter).
    gain_scale: float = 1.0
    sampler_seed: int = 0
    #: Seeds run between two reports to the pruner: part of the search (not
    #: of the machine), so a study prunes alike on any number of CPUs.
    chunk: int = 2

    def check(self) -> None:
        if self.law not in _native.LAWS:
            raise SystemExit(f"tune: --law {self.law!r} is not a law (one of {', '.join(_native.LAWS)})")
        if self.objective not in ("iae", "learning"):
            raise SystemExit(f"tune: --objective {self.objective!r}: iae or learning")
        if self.space not in ("all", "learning"):
            raise SystemExit(f"tune: --space {self.space!r}: all or learning")
        if self.objective == "learning" and (self.law != "nac" or self.space != "learning"):
            # nac-no-networks' runs are the same for every trial only when
            # the knobs searched are the networks' alone.
            raise SystemExit("tune: --objective learning needs --law nac and --space learning")
        for name, v, low in (("--trials", self.trials, 1), ("--seeds", self.seeds, 1),
                             ("--chunk", self.chunk, 1)):
            if v < low:
                raise SystemExit(f"tune: {name} {v}: at least {low}")
        if self.seeds > 1000:
            raise SystemExit(f"tune: --seeds {self.seeds}: at most 1000")
        if not (0.0 < self.gain_scale <= 1e3) or not math.isfinite(self.gain_scale):
            raise SystemExit(f"tune: --gain-scale {self.gain_scale}: a number in (0, 1000]")
        if self.duration is not None and not (0.0 < self.duration <= 1e4):
            raise SystemExit(f"tune: --duration {self.duration}: a time in (0, 10000] s")


def _toml():
    try:
        import tomllib
    except ImportError:  # Python < 3.11: the `tune` extra brings tomli
        import tomli as tomllib
    return tomllib


def _scenario_controller(scenario: str, robot: str | None) -> dict:
    tomllib = _toml()
    text = _native.scenario_toml(scenario, robot=robot)
    return tomllib.loads(text).get("controller", {})


def _scaled(g, s: float):
    return [x * s for x in g] if isinstance(g, list) else g * s


class Space:
    """A law's search space, as the parameter table declares it, with the
    scenario's gains the scale ranges multiply."""

    def __init__(self, setup: Setup):
        self.setup = setup
        ctrl = _scenario_controller(setup.scenario, setup.robot)
        self.base = {k: _scaled(ctrl.get(k, 15.0), setup.gain_scale) for k in ("k1", "k2")}
        dims = _native.search_space(setup.law)
        if setup.space == "learning":
            dims = [d for d in dims if d["role"] in ("actor", "critic")]
        fixed = {k.removeprefix("controller."): v for k, v in setup.fixed.items()}
        self.dims = [d for d in dims if d["key"] not in fixed]
        if not self.dims:
            raise SystemExit(f"tune: {setup.law} has nothing left to search ({setup.space} space, "
                             f"{len(fixed)} keys fixed)")

    def suggest(self, trial) -> dict:
        """The trial's values, as `set=` keys."""
        out = {}
        for d in self.dims:
            key, r = d["key"], d["range"]
            if r["kind"] == "float":
                v = trial.suggest_float(key, r["low"], r["high"], log=r["log"])
            elif r["kind"] == "int":
                v = trial.suggest_int(key, r["low"], r["high"], log=r["log"])
            elif r["kind"] == "scale":
                f = trial.suggest_float(f"{key}_scale", r["low"], r["high"], log=True)
                v = _scaled(self.base[key], f)
            elif r["kind"] == "choice":
                v = trial.suggest_categorical(key, list(r["choices"]))
            else:  # a new kind in the table: refuse rather than guess
                raise SystemExit(f"tune: {key}: unknown range kind {r['kind']!r}")
            out[f"controller.{key}"] = v
        return out

    def as_given(self) -> dict:
        """The scenario's own values as a trial's parameters (enqueued first,
        so every study tries what the law is given)."""
        ctrl = _scenario_controller(self.setup.scenario, self.setup.robot)
        defaults = {d["key"]: d for d in self.dims}
        out = {}
        for key, d in defaults.items():
            r = d["range"]
            if r["kind"] == "scale":
                out[f"{key}_scale"] = 1.0
                continue
            v = ctrl.get(key)
            if v is None:
                continue  # the law's default: left to the sampler's first draw
            if r["kind"] in ("float", "int") and not (r["low"] <= v <= r["high"]):
                continue
            out[key] = v
        return out

    def values(self, params: dict) -> dict:
        """A finished trial's parameters as `set=` keys."""
        out = {}
        for d in self.dims:
            key, r = d["key"], d["range"]
            if r["kind"] == "scale":
                out[f"controller.{key}"] = _scaled(self.base[key], params[f"{key}_scale"])
            else:
                out[f"controller.{key}"] = params[key]
        return out


def base_set(setup: Setup, space: Space) -> dict:
    """The keys every run of the study sets: the law, the fixed keys, the
    scaled gains, the duration."""
    s = {"controller.law": setup.law}
    s.update({f"controller.{k}": v for k, v in space.base.items()})
    s.update({k if k.startswith("controller.") or "." in k else f"controller.{k}": v
              for k, v in setup.fixed.items()})
    if setup.duration is not None:
        s["duration_s"] = setup.duration
    return s


def per_seed(table: dict, law: str) -> tuple[list[float], dict]:
    """Each seed's IAE after T_c for `law` (inf where the run left the
    envelope after T_c, failed, or has no IAE), and the counts."""
    row = next(r for r in table["laws"] if r["name"] == law)
    vals = []
    for run in row["runs"]:
        iae = run["summary"]["metrics"].get("iae_after_tc")
        bad = run["failed"] is not None or run["envelope"] != "kept" or iae is None
        vals.append(math.inf if bad else float(iae))
    counts = {k: row[k] for k in ("kept_envelope", "left_envelope", "not_judged", "failed")}
    return vals, counts


def _median(xs: list[float]) -> float:
    return float(statistics.median(xs)) if xs else math.inf


class Objective:
    """One trial: the law over the training seeds, in chunks of `chunk`
    seeds, reporting the running median after each so the pruner can stop
    a hopeless trial early."""

    def __init__(self, setup: Setup, space: Space, threads: int | None):
        self.setup, self.space, self.threads = setup, space, threads
        self.base = base_set(setup, space)
        self.chunk = setup.chunk
        self._reference: list[float] | None = None

    def runs(self, law: str, values: dict, first: int, n: int) -> tuple[list[float], dict]:
        s = dict(self.base)
        s.update(values)
        s["seed"] = first
        s["controller.law"] = law
        table = _native.compare(self.setup.scenario, robot=self.setup.robot, laws=[law],
                                seeds=n, set=s, threads=self.threads)
        return per_seed(table, law)

    def reference(self) -> list[float]:
        """nac-no-networks on the training seeds at the study's fixed knobs
        (the same for every trial of a learning study)."""
        if self._reference is None:
            vals, _ = self.runs(NO_NETWORKS, {}, self.setup.first_seed, self.setup.seeds)
            self._reference = vals
        return self._reference

    def __call__(self, trial, values: dict) -> float:
        optuna = _optuna()
        setup = self.setup
        scores: list[float] = []
        totals = {"kept_envelope": 0, "left_envelope": 0, "not_judged": 0, "failed": 0}
        ref = self.reference() if setup.objective == "learning" else None
        for start in range(0, setup.seeds, self.chunk):
            n = min(self.chunk, setup.seeds - start)
            vals, counts = self.runs(setup.law, values, setup.first_seed + start, n)
            for k in totals:
                totals[k] += counts[k]
            if ref is not None:
                vals = [v - r for v, r in zip(vals, ref[start:start + n])]
            scores.extend(vals)
            trial.report(_finite(_median(scores)), len(scores))
            if len(scores) < setup.seeds and trial.should_prune():
                trial.set_user_attr("seeds_run", len(scores))
                trial.set_user_attr("counts", totals)
                raise optuna.TrialPruned()
        trial.set_user_attr("seeds_run", len(scores))
        trial.set_user_attr("counts", totals)
        trial.set_user_attr("per_seed", [None if not math.isfinite(v) else v for v in scores])
        if ref is not None:
            trial.set_user_attr("reference_median", _finite(_median(ref)))
        return _finite(_median(scores))


def _finite(x: float) -> float:
    return x if math.isfinite(x) else WORST


# --- the study: storage, shared by processes, resumable ----------------------------


def storage(path: Path):
    """The study file: Optuna's JournalStorage on a file, which processes
    (and Slurm tasks on a shared file system) may write at once; SQLite is
    not safe for that (Optuna's docs)."""
    optuna = _optuna()
    from optuna.storages.journal import JournalFileBackend, JournalFileOpenLock

    path.parent.mkdir(parents=True, exist_ok=True)
    backend = JournalFileBackend(str(path), lock_obj=JournalFileOpenLock(str(path)))
    return optuna.storages.JournalStorage(backend)


class StudyLock:
    """Held while a process counts the trials and asks for a new one, so
    two processes never start the N+1-th trial. A lock file beside the
    study (fcntl, which a shared NFS v3+ file system honours)."""

    def __init__(self, path: Path):
        self.path = Path(str(path) + ".tune-lock")

    def __enter__(self):
        import fcntl

        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        fcntl.flock(self.fd, fcntl.LOCK_EX)
        return self

    def __exit__(self, *exc):
        import fcntl

        fcntl.flock(self.fd, fcntl.LOCK_UN)
        os.close(self.fd)


def _worker() -> dict:
    return {"host": socket.gethostname(), "pid": os.getpid(), "started": time.time()}


def _alive(w: dict, stale_after: float) -> bool:
    """Whether the process that runs a trial is still running it: on this
    host by its pid; on another, while the trial is younger than
    `stale_after` seconds."""
    if not w:
        return True  # a trial from outside `tune` (optuna's own API): leave it
    if w.get("host") == socket.gethostname():
        try:
            os.kill(int(w["pid"]), 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True
    return time.time() - float(w.get("started", 0)) < stale_after


def recover(study, stale_after: float) -> int:
    """Fails each trial whose process died while running it (kill -9, a
    lost node) and enqueues its parameters again, so the search loses no
    point and counts none twice. Returns how many were recovered."""
    optuna = _optuna()
    n = 0
    for t in study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.RUNNING,)):
        if _alive(t.system_attrs.get("tune_worker", {}), stale_after):
            continue
        study._storage.set_trial_state_values(t._trial_id, optuna.trial.TrialState.FAIL)
        if t.params:
            study.enqueue_trial(t.params, user_attrs={"retry_of": t.number},
                                skip_if_exists=False)
        n += 1
    return n


def _counted(study) -> int:
    """Trials that count toward the budget: finished (complete or pruned)
    and running."""
    optuna = _optuna()
    TS = optuna.trial.TrialState
    return len(study.get_trials(deepcopy=False, states=(TS.COMPLETE, TS.PRUNED, TS.RUNNING)))


def open_study(path: Path, name: str, setup: Setup | None):
    """The study `name` in `path`: made with `setup`, or checked against it
    (a resumed or shared study must be the same search); `setup` None
    only opens it."""
    optuna = _optuna()
    st = storage(path)
    sampler = None
    if setup is not None:
        sampler = optuna.samplers.TPESampler(seed=setup.sampler_seed, multivariate=True,
                                             constant_liar=True)
    pruner = optuna.pruners.MedianPruner(n_startup_trials=10, n_warmup_steps=0)
    names = {s.study_name for s in st.get_all_studies()}
    if setup is None:
        if name not in names:
            raise SystemExit(f"tune: {path}: no study {name!r} (it holds {', '.join(sorted(names)) or 'none'})")
        return optuna.load_study(study_name=name, storage=st), None
    with StudyLock(path):
        study = optuna.create_study(study_name=name, storage=st, sampler=sampler, pruner=pruner,
                                    direction="minimize", load_if_exists=True)
        stored = study.user_attrs.get("setup")
        mine = asdict(setup)
        if stored is None:
            study.set_user_attr("setup", mine)
            study.set_user_attr("space", Space(setup).dims)
            study.enqueue_trial(Space(setup).as_given(), user_attrs={"as_given": True})
        else:
            diff = [k for k in mine if k != "trials" and stored.get(k) != mine[k]]
            if diff:
                k = diff[0]
                raise SystemExit(f"tune: {path}: study {name!r} was made with {k} = {stored.get(k)!r}, "
                                 f"not {mine[k]!r}: use another --study or the same options")
            if mine["trials"] != stored["trials"]:
                study.set_user_attr("setup", mine)  # a larger budget resumes further
    return study, setup


def run(path: Path, name: str, setup: Setup, threads: int | None, stale_after: float,
        progress: bool) -> int:
    """Runs trials until the study has `setup.trials` of them; returns how
    many this process ran."""
    optuna = _optuna()
    setup.check()
    study, _ = open_study(path, name, setup)
    space = Space(setup)
    objective = Objective(setup, space, threads)
    with StudyLock(path):
        recovered = recover(study, stale_after)
    if recovered:
        print(f"tune: {recovered} trial(s) whose process died are run again", file=sys.stderr)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=setup.trials, initial=min(_counted(study), setup.trials),
                   desc=f"{name}", unit="trial", file=sys.stderr)
    ran = 0
    while True:
        with StudyLock(path):
            if _counted(study) >= setup.trials:
                break
            trial = study.ask()
            study._storage.set_trial_system_attr(trial._trial_id, "tune_worker", _worker())
        try:
            values = space.suggest(trial)
            value = objective(trial, values)
            study.tell(trial, value)
        except optuna.TrialPruned:
            study.tell(trial, state=optuna.trial.TrialState.PRUNED)
        except _native.TestbedError as e:
            # A point the law refuses (a key combination the checks reject):
            # the worst value, and the reason kept.
            trial.set_user_attr("refused", str(e)[:300])
            study.tell(trial, WORST)
        except BaseException:
            # Ctrl-C or a bug: the trial is failed, not left running, and
            # its parameters are tried again on resume.
            study.tell(trial, state=optuna.trial.TrialState.FAIL)
            study.enqueue_trial(trial.params, user_attrs={"retry_of": trial.number})
            raise
        ran += 1
        if bar is not None:
            bar.update(1)
            best = _best(study)
            if best is not None:
                bar.set_postfix(best=f"{best.value:.4g}")
    if bar is not None:
        bar.close()
    return ran


# --- reading a study -------------------------------------------------------------------


def _best(study):
    optuna = _optuna()
    done = [t for t in study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
            if t.value is not None]
    return min(done, key=lambda t: (t.value, t.number)) if done else None


def summary(path: Path, name: str | None) -> dict:
    """What a study found, as `report --json` prints it."""
    optuna = _optuna()
    name = name or _only_study(path)
    study, _ = open_study(path, name, None)
    setup = Setup(**study.user_attrs["setup"])
    TS = optuna.trial.TrialState
    states = {s.name.lower(): len(study.get_trials(deepcopy=False, states=(s,))) for s in TS}
    best = _best(study)
    given = next((t for t in study.get_trials(deepcopy=False, states=(TS.COMPLETE,))
                  if t.user_attrs.get("as_given")), None)
    out = {"study": name, "file": str(path), "setup": asdict(setup), "trials": states,
           "space": study.user_attrs.get("space", [])}
    space = Space(setup)
    for label, t in (("best", best), ("as_given", given)):
        if t is None:
            out[label] = None
            continue
        out[label] = {"number": t.number, "value": t.value, "params": t.params,
                      "set": {**base_set(setup, space), **space.values(t.params)},
                      "counts": t.user_attrs.get("counts"),
                      "per_seed": t.user_attrs.get("per_seed"),
                      "reference_median": t.user_attrs.get("reference_median")}
    return out


def _only_study(path: Path) -> str:
    if not path.is_file():
        raise SystemExit(f"tune: {path}: no such study file")
    names = sorted(s.study_name for s in storage(path).get_all_studies())
    if len(names) != 1:
        raise SystemExit(f"tune: {path} holds {len(names)} studies ({', '.join(names)}): name one with --study")
    return names[0]


def law_set(s: dict) -> dict:
    """A best trial's keys as `law_sets` / `--law-set` take them: the
    controller keys of one law (duration and seed stay the comparison's)."""
    return {k: v for k, v in s.items() if k.startswith("controller.") and k != "controller.law"}


def scenario_text(rep: dict, dir: Path) -> str:
    """The best trial as a scenario file (to write in folder `dir`) the CLI
    runs as it is: the scenario as authored, randomised draws and all, with
    the trial's controller keys."""
    setup = rep["setup"]
    s = dict(rep["best"]["set"])
    s.pop("duration_s", None)  # the scenario's own: evaluation runs it whole
    s["name"] = f"{Path(setup['scenario']).stem}_{setup['law'].replace('-', '_')}_tuned"
    head = (f"# The best of {sum(rep['trials'].get(k, 0) for k in ('complete', 'pruned'))} trials "
            f"of `testbed tune` for {setup['law']} on {setup['scenario']}\n"
            f"# (objective {setup['objective']}: {rep['best']['value']:.6g} on seeds "
            f"{setup['first_seed']}..{setup['first_seed'] + setup['seeds'] - 1}, "
            f"{setup['duration']} s; study {rep['study']} in {rep['file']}).\n"
            f"# Run it: testbed compare --scenario THIS_FILE --laws {setup['law']} --seeds 20\n")
    return head + _native.scenario_file(setup["scenario"], dir=str(dir), robot=setup["robot"], set=s)


# --- held-out evaluation -------------------------------------------------------------


def evaluate(reports: list[dict], scenario: str, robot: str | None, seeds: int, first_seed: int,
             duration: float | None, extra: list[str], threads: int | None,
             stress: dict | None = None) -> dict:
    """Each study's best trial on seeds no study used, in one comparison
    (its paired tests and Holm over them; each row's IQM and its bootstrap
    interval are the comparison's own)."""
    used = [(r["setup"]["first_seed"], r["setup"]["first_seed"] + r["setup"]["seeds"]) for r in reports]
    for lo, hi in used:
        if first_seed < hi and lo < first_seed + seeds:
            raise SystemExit(f"tune: evaluation seeds {first_seed}..{first_seed + seeds - 1} overlap "
                             f"training seeds {lo}..{hi - 1}: pick --first-seed outside them")
    laws, law_sets = [], {}
    for r in reports:
        law = r["setup"]["law"]
        if law in law_sets:
            raise SystemExit(f"tune: two studies of {law}: evaluate one per law")
        laws.append(law)
        law_sets[law] = law_set(r["best"]["set"])
    laws += [x for x in extra if x not in laws]
    s = {"seed": first_seed}
    if duration is not None:
        s["duration_s"] = duration
    s.update(stress or {})
    table = _native.compare(scenario, robot=robot, laws=laws, seeds=seeds, set=s,
                            threads=threads, law_sets=law_sets)
    return {"comparison": table, "rows": [row_stats(table, law) for law in laws]}


def row_stats(table: dict, law: str) -> dict:
    vals, counts = per_seed(table, law)
    row = next(r for r in table["laws"] if r["name"] == law)
    ci = (row["iqm_ci95_low"].get("iae"), row["iqm_ci95_high"].get("iae"))
    return {"law": law, "median_iae": _median(vals), "iqm_iae": row["iqm"].get("iae"),
            "iqm_ci95": ci, "torque_rate_median": row["median"].get("torque_rate"), **counts}


# --- command line --------------------------------------------------------------------


def _fixed(items: list[str]) -> dict:
    tomllib = _toml()

    out = {}
    for it in items:
        key, eq, text = it.partition("=")
        if not eq or not key.strip():
            raise SystemExit(f"tune: --fixed {it!r}: KEY=VALUE")
        try:
            out[key.strip()] = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            out[key.strip()] = text
    return out


def _study_path(args) -> Path:
    if args.storage:
        return Path(args.storage)
    return Path("studies") / f"{args.study or default_name(args)}.journal"


def default_name(args) -> str:
    scen = Path(args.scenario).stem
    tag = "" if args.objective == "iae" else f"-{args.objective}"
    gs = "" if args.gain_scale == 1.0 else f"-k{args.gain_scale:g}"
    return f"{args.law}-{scen}{gs}{tag}"


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.5g}"
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)


def print_report(rep: dict) -> None:
    s = rep["setup"]
    t = rep["trials"]
    print(f"study {rep['study']} ({rep['file']}): {s['law']} on {s['scenario']}, objective {s['objective']}, "
          f"space {s['space']}")
    print(f"  budget {s['trials']} trials: {t.get('complete', 0)} complete, {t.get('pruned', 0)} pruned, "
          f"{t.get('fail', 0)} failed, {t.get('running', 0)} running; "
          f"training seeds {s['first_seed']}..{s['first_seed'] + s['seeds'] - 1}, {s['duration']} s; "
          f"TPE seed {s['sampler_seed']}")
    for label in ("as_given", "best"):
        b = rep[label]
        if b is None:
            print(f"  {label}: none yet")
            continue
        c = b["counts"] or {}
        print(f"  {label.replace('_', ' ')} (trial {b['number']}): objective {b['value']:.6g}; "
              f"kept {c.get('kept_envelope', '?')}, left {c.get('left_envelope', '?')}, "
              f"failed {c.get('failed', '?')}")
        for k, v in b["set"].items():
            print(f"      {k} = {_fmt(v)}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="testbed tune", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run (or resume, or join) a study until it has --trials trials")
    r.add_argument("--law", required=True)
    r.add_argument("--scenario", required=True, help="a shipped scenario's name or a TOML file")
    r.add_argument("--robot")
    r.add_argument("--trials", type=int, default=200)
    r.add_argument("--seeds", type=int, default=8, help="training seeds")
    r.add_argument("--first-seed", type=int, default=1000)
    r.add_argument("--duration", type=float, default=4.0, help="seconds of each training run")
    r.add_argument("--objective", choices=["iae", "learning"], default="iae")
    r.add_argument("--space", choices=["all", "learning"], default="all")
    r.add_argument("--fixed", action="append", default=[], metavar="KEY=VALUE")
    r.add_argument("--gain-scale", type=float, default=1.0)
    r.add_argument("--sampler-seed", type=int, default=0)
    r.add_argument("--chunk", type=int, default=2, help="seeds between two reports to the pruner")
    r.add_argument("--study", help="the study's name (default: LAW-SCENARIO[-kSCALE][-learning])")
    r.add_argument("--storage", help="the study file (default: studies/NAME.journal)")
    r.add_argument("--threads", type=int)
    r.add_argument("--stale-after", type=float, default=3600.0,
                   help="a running trial of another host older than this (s) is taken as lost")
    r.add_argument("--no-progress", action="store_true")
    for name, helptext in (("report", "what a study found"), ("best", "a study's best trial")):
        q = sub.add_parser(name, help=helptext)
        q.add_argument("file")
        q.add_argument("--study")
        q.add_argument("--json", action="store_true")
        if name == "best":
            q.add_argument("--write-scenario", metavar="FILE")
    e = sub.add_parser("evaluate", help="each study's best trial on held-out seeds, compared")
    e.add_argument("files", nargs="+")
    e.add_argument("--seeds", type=int, default=20)
    e.add_argument("--first-seed", type=int, default=10000)
    e.add_argument("--duration", type=float, help="default: the scenario's")
    e.add_argument("--also", default="", help="laws compared untuned beside them (comma-separated)")
    e.add_argument("--threads", type=int)
    e.add_argument("--json", action="store_true")
    sp = sub.add_parser("space", help="a law's search space")
    sp.add_argument("law")
    args = p.parse_args(argv)

    if args.cmd == "space":
        for d in _native.search_space(args.law):
            print(f"{d['key']:16} {d['role']:7} {_describe(d['range'])}")
        return 0
    if args.cmd == "run":
        setup = Setup(law=args.law, scenario=args.scenario, robot=args.robot, trials=args.trials,
                      seeds=args.seeds, first_seed=args.first_seed, duration=args.duration,
                      objective=args.objective, space=args.space, fixed=_fixed(args.fixed),
                      gain_scale=args.gain_scale, sampler_seed=args.sampler_seed,
                      chunk=args.chunk)
        setup.check()
        path = _study_path(args)
        name = args.study or default_name(args)
        progress = not args.no_progress and sys.stderr.isatty()
        ran = run(path, name, setup, args.threads, args.stale_after, progress)
        rep = summary(path, name)
        print(f"tune: ran {ran} trial(s) of {setup.trials}")
        print_report(rep)
        return 0
    if args.cmd in ("report", "best"):
        rep = summary(Path(args.file), args.study)
        if args.cmd == "best" and args.write_scenario:
            if rep["best"] is None:
                raise SystemExit(f"tune: {args.file}: no complete trial yet")
            out = Path(args.write_scenario)
            out.write_text(scenario_text(rep, out.resolve().parent))
            print(f"tune: wrote {args.write_scenario}", file=sys.stderr)
        if args.json:
            print(json.dumps(rep if args.cmd == "report" else rep["best"], indent=1))
        else:
            print_report(rep)
        return 0
    if args.cmd == "evaluate":
        reps = [summary(Path(f), None) for f in args.files]
        scen = {(r["setup"]["scenario"], r["setup"]["robot"]) for r in reps}
        if len(scen) != 1:
            raise SystemExit("tune: evaluate compares studies of one scenario and robot")
        (scenario, robot), = scen
        out = evaluate(reps, scenario, robot, args.seeds, args.first_seed, args.duration,
                       [x for x in args.also.split(",") if x], args.threads)
        if args.json:
            print(json.dumps(out["rows"], indent=1))
        else:
            print(f"held-out seeds {args.first_seed}..{args.first_seed + args.seeds - 1}")
            for row in out["rows"]:
                lo, hi = (x if x is not None else math.inf for x in row["iqm_ci95"])
                iq = row["iqm_iae"] if row["iqm_iae"] is not None else math.inf
                print(f"  {row['law']:16} median IAE {row['median_iae']:.4g}  IQM {iq:.4g} "
                      f"[{lo:.4g}, {hi:.4g}]  kept {row['kept_envelope']}/{args.seeds}")
        return 0
    return 2


def _describe(r: dict) -> str:
    k = r["kind"]
    if k == "float":
        return f"[{r['low']:g}, {r['high']:g}] {'log' if r['log'] else 'linear'}"
    if k == "int":
        return f"integer [{r['low']}, {r['high']}] {'log' if r['log'] else 'linear'}"
    if k == "scale":
        return f"x[{r['low']:g}, {r['high']:g}] of the scenario's value, per joint, log"
    return "one of " + ", ".join(r["choices"])


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:
        sys.exit(141)
