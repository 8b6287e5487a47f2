"""Reading the three inputs: measured data, the baseline model, the catalogue
of candidate extensions. File formats are documented in doc/discrepancy.md."""
import csv
import json
import math
import os

RESERVED = ("observable", "value", "uncertainty")


class InputFileError(Exception):
    pass


def _float(text, where):
    try:
        return float(text)
    except ValueError:
        raise InputFileError(f"{where}: '{text}' is not a number")


class Data:
    """Measured points: condition columns, observable name, value, uncertainty."""

    def __init__(self, conditions, rows, source):
        self.conditions = list(conditions)  # names of the condition columns
        self.rows = rows  # dicts: cond (tuple of floats), observable, value, sigma
        self.source = source

    def __len__(self):
        return len(self.rows)

    def observables(self):
        seen = []
        for r in self.rows:
            if r["observable"] not in seen:
                seen.append(r["observable"])
        return seen


def _read_csv_lines(path):
    with open(path, newline="") as f:
        lines = [ln for ln in f if ln.strip() and not ln.lstrip().startswith("#")]
    return list(csv.reader(lines))


def read_long_csv(path):
    """CSV with condition columns plus 'observable', 'value', 'uncertainty'."""
    table = _read_csv_lines(path)
    if not table:
        raise InputFileError(f"{path}: no header line")
    header = [h.strip() for h in table[0]]
    for col in RESERVED:
        if col not in header:
            raise InputFileError(f"{path}: missing column '{col}' (header: {', '.join(header)}); "
                                 "the data file needs condition columns plus observable,value,uncertainty")
    conds = [h for h in header if h not in RESERVED]
    if not conds:
        raise InputFileError(f"{path}: no condition column besides observable,value,uncertainty")
    rows = []
    for k, rec in enumerate(table[1:], start=2):
        if len(rec) != len(header):
            raise InputFileError(f"{path}: data line {k} has {len(rec)} fields, header has {len(header)}")
        d = dict(zip(header, (x.strip() for x in rec)))
        sigma = _float(d["uncertainty"], f"{path} line {k}")
        if not sigma > 0:
            raise InputFileError(f"{path} line {k}: uncertainty must be > 0")
        rows.append({"cond": tuple(_float(d[c], f"{path} line {k}") for c in conds),
                     "observable": d["observable"], "value": _float(d["value"], f"{path} line {k}"),
                     "sigma": sigma})
    return Data(conds, rows, path)


def _sigma(spec, value, where):
    if isinstance(spec, (int, float)):
        return float(spec)
    if isinstance(spec, dict):
        rel = float(spec.get("relative", 0.0))
        absolute = float(spec.get("absolute", 0.0))
        floor = float(spec.get("floor", 0.0))
        return max(math.hypot(rel * abs(value), absolute), floor)
    raise InputFileError(f"{where}: 'uncertainty' must be a number or {{relative, absolute, floor}}")


def read_data_spec(path):
    """JSON that assembles data from wide CSV files (one condition column and
    one value column each, paths relative to the JSON file) and states their
    uncertainty."""
    with open(path) as f:
        spec = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    cond_name = spec.get("condition")
    rows = []
    for k, item in enumerate(spec.get("files", [])):
        where = f"{path}: files[{k}]"
        fpath = os.path.join(base, item["path"])
        if not os.path.exists(fpath):
            raise InputFileError(f"{where}: data file '{fpath}' not found")
        table = _read_csv_lines(fpath)
        header = [h.strip() for h in table[0]]
        c_col = item.get("condition_column", header[0])
        v_col = item.get("value_column", header[1])
        if c_col not in header or v_col not in header:
            raise InputFileError(f"{where}: columns '{c_col}', '{v_col}' not in {fpath}")
        ci, vi = header.index(c_col), header.index(v_col)
        for rec in table[1:]:
            value = _float(rec[vi], fpath)
            rows.append({"cond": (_float(rec[ci], fpath),), "observable": item["observable"],
                         "value": value, "sigma": _sigma(item["uncertainty"], value, where)})
    if not rows:
        raise InputFileError(f"{path}: no data rows")
    return Data([cond_name or "condition"], rows, path)


def read_data(path):
    if not os.path.exists(path):
        raise InputFileError(f"data file '{path}' not found")
    if path.endswith(".json"):
        return read_data_spec(path)
    return read_long_csv(path)


class Param:
    def __init__(self, d, where):
        if "name" not in d:
            raise InputFileError(f"{where}: each parameter needs a 'name'")
        self.name = d["name"]
        self.var = d.get("var", self.name)
        # A choice parameter takes one of a set of allowed values (e.g. the
        # spheres per clump of the clump files that exist); the fit tries
        # every value, so it needs no bounds and has no gradient.
        self.choices = None
        if "choices" in d:
            ch = d["choices"]
            if not isinstance(ch, list) or len(ch) < 2:
                raise InputFileError(f"{where}: parameter '{self.name}': 'choices' must be a list of at least "
                                     "two values")
            try:
                self.choices = sorted(float(x) for x in ch)
            except (TypeError, ValueError):
                raise InputFileError(f"{where}: parameter '{self.name}': 'choices' must be numbers")
            if len(set(self.choices)) != len(self.choices):
                raise InputFileError(f"{where}: parameter '{self.name}': 'choices' has repeated values")
            for key in ("lower", "upper", "scale", "integer"):
                if key in d:
                    raise InputFileError(f"{where}: parameter '{self.name}': '{key}' cannot go with 'choices' "
                                         "(the choices are the allowed values)")
            self.lower, self.upper = self.choices[0], self.choices[-1]
            self.scale = "linear"
            self.integer = False
        else:
            try:
                self.lower = float(d["lower"])
                self.upper = float(d["upper"])
            except KeyError as e:
                raise InputFileError(f"{where}: parameter '{self.name}' needs {e} (or 'choices')")
            self.scale = d.get("scale", "linear")
            if self.scale not in ("linear", "log"):
                raise InputFileError(f"{where}: parameter '{self.name}': scale must be linear or log")
            if not self.upper > self.lower or (self.scale == "log" and self.lower <= 0):
                raise InputFileError(f"{where}: parameter '{self.name}': need lower < upper (and lower > 0 "
                                     "for log)")
            # Discrete parameters (e.g. spheres per clump) are rounded; the coarse
            # scan finds them, the local fit then leaves them where they are.
            self.integer = bool(d.get("integer", False))
        self.initial = float(d["initial"]) if "initial" in d else None
        if self.choices is not None and self.initial is not None and self.initial not in self.choices:
            raise InputFileError(f"{where}: parameter '{self.name}': initial {self.initial:g} is not one of "
                                 "the choices")

    @property
    def discrete(self):
        return self.choices is not None

    # unit interval <-> parameter value (choices: equally spaced in the unit
    # interval, in ascending order)
    def to_value(self, u):
        u = min(max(u, 0.0), 1.0)
        if self.choices is not None:
            return self.choices[int(round(u * (len(self.choices) - 1)))]
        if self.scale == "log":
            x = math.exp(math.log(self.lower) + u * (math.log(self.upper) - math.log(self.lower)))
        else:
            x = self.lower + u * (self.upper - self.lower)
        return float(round(x)) if self.integer else x

    def to_unit(self, x):
        if self.choices is not None:
            k = min(range(len(self.choices)), key=lambda i: abs(self.choices[i] - x))
            return k / (len(self.choices) - 1)
        if self.scale == "log":
            return (math.log(x) - math.log(self.lower)) / (math.log(self.upper) - math.log(self.lower))
        return (x - self.lower) / (self.upper - self.lower)

    def dvalue_du(self, u):
        if self.choices is not None:
            return math.nan
        if self.scale == "log":
            return self.to_value(u) * (math.log(self.upper) - math.log(self.lower))
        return self.upper - self.lower

    def to_json(self):
        d = {"name": self.name, "var": self.var, "lower": self.lower, "upper": self.upper,
             "scale": self.scale, "integer": self.integer}
        if self.choices is not None:
            d["choices"] = self.choices
        return d


class Model:
    """The baseline: script, condition variables, fixed settings, free params, extraction."""

    def __init__(self, path):
        with open(path) as f:
            d = json.load(f)
        self.path = path
        self.dir = os.path.dirname(os.path.abspath(path))
        self.name = d.get("name", os.path.basename(path))
        if "script" not in d:
            raise InputFileError(f"{path}: 'script' (the input script) is required")
        self.script = os.path.join(self.dir, d["script"])
        if not os.path.exists(self.script):
            raise InputFileError(f"{path}: script '{self.script}' not found")
        self.conditions = d.get("conditions", {})  # data column -> script variable
        self.set = {k: str(v) for k, v in d.get("set", {}).items()}
        # Settings that are paths relative to the model file (the runs work in
        # temporary directories): passed as absolute paths.
        for k, v in d.get("paths", {}).items():
            full = os.path.normpath(os.path.join(self.dir, str(v)))
            if not os.path.exists(full):
                raise InputFileError(f"{path}: paths: '{k}' -> '{full}' not found")
            self.set[k] = full
        self.params = [Param(p, path) for p in d.get("params", [])]
        ex = d.get("extract", {})
        self.extract = ex
        self.prefix = ex.get("prefix", "DISCREPANCY")
        self.result_file = ex.get("file")  # None: parse the screen output
        self.observables = d.get("observables", {})  # data observable -> printed key
        self.timeout = float(d.get("timeout_s", 120))
        self.plot_x = d.get("plot_x")
        self.log_x = bool(d.get("plot_log_x", False))

    def check_data(self, data):
        for c in data.conditions:
            if c not in self.conditions:
                raise InputFileError(f"{self.path}: data condition column '{c}' has no script variable in "
                                     f"'conditions' (have: {', '.join(self.conditions) or 'none'})")

    def key_of(self, observable):
        return self.observables.get(observable, observable)


class Candidate:
    def __init__(self, d, where):
        if "name" not in d:
            raise InputFileError(f"{where}: each candidate needs a 'name'")
        self.name = d["name"]
        self.mechanism = d.get("mechanism", self.name)
        self.description = d.get("description", "")
        self.set = {k: str(v) for k, v in d.get("set", {}).items()}
        self.drop = list(d.get("drop", []))  # baseline params this extension makes unused
        self.params = [Param(p, f"{where}: candidate '{self.name}'") for p in d.get("params", [])]


def read_candidates(path):
    with open(path) as f:
        d = json.load(f)
    items = d.get("candidates", d if isinstance(d, list) else None)
    if not items:
        raise InputFileError(f"{path}: no 'candidates' list")
    cands = [Candidate(c, path) for c in items]
    names = [c.name for c in cands]
    if len(set(names)) != len(names):
        raise InputFileError(f"{path}: candidate names must be unique")
    return cands
