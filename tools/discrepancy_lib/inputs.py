"""Reading the three inputs: measured data, the baseline model, the catalogue
of candidate extensions. File formats are documented in doc/discrepancy.md."""
import csv
import json
import math
import os
import re

RESERVED = ("observable", "value", "uncertainty")


class InputFileError(Exception):
    pass


class Data:
    """Measured points: condition columns, observable name, value, uncertainty."""

    def __init__(self, conditions, rows, source, units=None):
        self.conditions = list(conditions)  # names of the condition columns
        self.rows = rows  # dicts: cond (tuple of floats), observable, value, sigma
        self.source = source
        self.units = dict(units or {})  # column name -> unit from the header

    def __len__(self):
        return len(self.rows)

    def observables(self):
        seen = []
        for r in self.rows:
            if r["observable"] not in seen:
                seen.append(r["observable"])
        return seen


def _read_table(path):
    """Non-comment, non-blank CSV records with their line numbers in the file."""
    with open(path, newline="") as f:
        numbered = [(k, ln) for k, ln in enumerate(f, start=1) if ln.strip() and not ln.lstrip().startswith("#")]
    return [(k, rec) for (k, _), rec in zip(numbered, csv.reader([ln for _, ln in numbered]))]


_UNIT = re.compile(r"^(.*?)\s*[\[(]([^\])]*)[\])]\s*$")


def split_unit(text):
    """'impact_speed [m/s]' or 'impact_speed (m/s)' -> ('impact_speed', 'm/s')."""
    text = text.strip()
    m = _UNIT.match(text)
    if m and m.group(1):
        return m.group(1).strip(), m.group(2).strip()
    return text, ""


# Names of an uncertainty column: shared ('uncertainty') or of one observable
# ('restitution_uncertainty').
UNCERTAINTY_WORDS = ("uncertainty", "sigma", "error")


def _header(path, table):
    if not table:
        raise InputFileError(f"{path}: no header line; the first line that is not a comment must name the "
                             "columns (e.g. 'speed,restitution,uncertainty')")
    line, rec = table[0]
    names, units = [], {}
    for col, h in enumerate(rec, start=1):
        name, unit = split_unit(h)
        if not name:
            raise InputFileError(f"{path} line {line}: column {col} of the header has no name; name every column")
        if name in names:
            raise InputFileError(f"{path} line {line}: column '{name}' appears twice in the header; rename one")
        names.append(name)
        if unit:
            units[name] = unit
    return line, names, units


def _number(text, path, line, col, what):
    try:
        x = float(text)
    except ValueError:
        raise InputFileError(f"{path} line {line}: {what} (column '{col}') is '{text}', not a number; "
                             "write a plain number (e.g. 0.5 or 1e-3), or comment the line out with '#'")
    if not math.isfinite(x):
        raise InputFileError(f"{path} line {line}: {what} (column '{col}') is '{text}'; values must be finite")
    return x


def _sigma_value(text, path, line, col):
    sigma = _number(text, path, line, col, "the uncertainty")
    if not sigma > 0:
        raise InputFileError(f"{path} line {line}: uncertainty (column '{col}') is {text}; it must be > 0 (one "
                             "standard deviation of the measured value)")
    return sigma


def _records(path, table, names):
    for line, rec in table[1:]:
        if len(rec) != len(names):
            raise InputFileError(f"{path} line {line}: {len(rec)} fields, the header has {len(names)} "
                                 f"({', '.join(names)}); every line needs one value per column")
        yield line, dict(zip(names, (x.strip() for x in rec)))


def read_csv(path, conditions=None):
    """Measured data in the long layout (condition columns plus observable,
    value, uncertainty) or the wide layout (condition columns, one column per
    observable, uncertainty columns); units in brackets in the header.
    `conditions`: the condition names the model knows (for the wide layout)."""
    table = _read_table(path)
    hline, names, units = _header(path, table)
    rows = []
    if "observable" in names or "value" in names:  # long layout
        for col in RESERVED:
            if col not in names:
                raise InputFileError(f"{path} line {hline}: missing column '{col}' (header: {', '.join(names)}); "
                                     "the long layout needs condition columns plus observable,value,uncertainty")
        conds = [h for h in names if h not in RESERVED]
        if not conds:
            raise InputFileError(f"{path} line {hline}: no condition column besides observable,value,uncertainty")
        for line, d in _records(path, table, names):
            rows.append({"cond": tuple(_number(d[c], path, line, c, "the condition") for c in conds),
                         "observable": d["observable"], "value": _number(d["value"], path, line, "value", "the value"),
                         "sigma": _sigma_value(d["uncertainty"], path, line, "uncertainty")})
        if not rows:
            raise InputFileError(f"{path}: no data lines after the header")
        return Data(conds, rows, path, units)
    # Wide layout.
    if conditions:
        conds = [h for h in names if h in conditions]
        if not conds:
            raise InputFileError(f"{path} line {hline}: no condition column; the model's conditions are "
                                 f"{', '.join(conditions)} (header: {', '.join(names)}); name the condition column "
                                 "after one of them, or map the column to a script variable in the model's "
                                 "'conditions'")
    else:
        conds = names[:1]
    rest = [h for h in names if h not in conds]
    shared = [h for h in rest if h in UNCERTAINTY_WORDS]
    own = {}
    for h in rest:
        for w in UNCERTAINTY_WORDS:
            if h.endswith("_" + w) and h not in shared:
                own[h[:-len(w) - 1]] = h
    observables = [h for h in rest if h not in shared and h not in own.values()]
    for obs, col in own.items():
        if obs not in observables:
            raise InputFileError(f"{path} line {hline}: uncertainty column '{col}' belongs to no value column "
                                 f"'{obs}' (value columns: {', '.join(observables) or 'none'}); rename it")
    if not observables:
        raise InputFileError(f"{path} line {hline}: no value column (header: {', '.join(names)}); the wide layout "
                             "is condition column(s), one column per observable and its uncertainty, e.g. "
                             "'speed,restitution,uncertainty'")
    if len(shared) > 1:
        raise InputFileError(f"{path} line {hline}: more than one shared uncertainty column ({', '.join(shared)}); "
                             "keep one, or name them '<observable>_uncertainty'")
    unc = {}
    for obs in observables:
        if obs in own:
            unc[obs] = own[obs]
        elif shared and len([o for o in observables if o not in own]) == 1:
            unc[obs] = shared[0]
        else:
            raise InputFileError(f"{path} line {hline}: no uncertainty column for '{obs}'; add a column "
                                 f"'{obs}_uncertainty' (one standard deviation per row), or with a single "
                                 "observable a column 'uncertainty'")
    for line, d in _records(path, table, names):
        cond = tuple(_number(d[c], path, line, c, "the condition") for c in conds)
        for obs in observables:
            if d[obs] == "" and d[unc[obs]] == "":
                continue  # not measured at this condition
            rows.append({"cond": cond, "observable": obs, "value": _number(d[obs], path, line, obs, "the value"),
                         "sigma": _sigma_value(d[unc[obs]], path, line, unc[obs])})
    if not rows:
        raise InputFileError(f"{path}: no data lines after the header")
    return Data(conds, rows, path, units)


def _sigma(spec, value, where):
    if isinstance(spec, (int, float)):
        return float(spec)
    if isinstance(spec, dict):
        rel = float(spec.get("relative", 0.0))
        absolute = float(spec.get("absolute", 0.0))
        floor = float(spec.get("floor", 0.0))
        return max(math.hypot(rel * abs(value), absolute), floor)
    raise InputFileError(f"{where}: 'uncertainty' must be a number, {{relative, absolute, floor}} or the name of "
                         "an uncertainty column")


def read_data_spec(path):
    """JSON that assembles data from CSV files with one condition column, a
    value column and optionally an uncertainty column each (paths relative to
    the JSON file), and states their uncertainty where the file has none."""
    try:
        with open(path) as f:
            spec = json.load(f)
    except json.JSONDecodeError as e:
        raise InputFileError(f"{path} line {e.lineno}: not valid JSON ({e.msg})")
    base = os.path.dirname(os.path.abspath(path))
    cond_name = spec.get("condition")
    rows, units = [], {}
    for k, item in enumerate(spec.get("files", [])):
        where = f"{path}: files[{k}]"
        for key in ("path", "observable"):
            if key not in item:
                raise InputFileError(f"{where}: '{key}' is required")
        fpath = os.path.join(base, item["path"])
        if not os.path.exists(fpath):
            raise InputFileError(f"{where}: data file '{fpath}' not found")
        table = _read_table(fpath)
        hline, header, file_units = _header(fpath, table)
        c_col = split_unit(item.get("condition_column", header[0]))[0]
        v_col = split_unit(item.get("value_column", header[1] if len(header) > 1 else ""))[0]
        for col in (c_col, v_col):
            if col not in header:
                raise InputFileError(f"{where}: column '{col}' not in {fpath} (header line {hline}: "
                                     f"{', '.join(header)})")
        # The uncertainty: a column of the file (named, or found by its name),
        # else the number or rule given here.
        u_spec = item.get("uncertainty")
        u_col = item.get("uncertainty_column", u_spec if isinstance(u_spec, str) else None)
        if u_col is None:
            found = [h for h in header if h in UNCERTAINTY_WORDS or h in (v_col + "_" + w for w in UNCERTAINTY_WORDS)]
            if found and u_spec is None:
                u_col = found[0]
        if u_col is not None:
            u_col = split_unit(u_col)[0]
            if u_col not in header:
                raise InputFileError(f"{where}: uncertainty column '{u_col}' not in {fpath} (header line "
                                     f"{hline}: {', '.join(header)})")
        elif u_spec is None:
            raise InputFileError(f"{where}: no uncertainty for '{item['observable']}': give 'uncertainty' (a "
                                 "number, {relative, absolute, floor} or a column name) or add a column "
                                 f"'uncertainty' to {fpath}")
        for line, d in _records(fpath, table, header):
            value = _number(d[v_col], fpath, line, v_col, "the value")
            sigma = (_sigma_value(d[u_col], fpath, line, u_col) if u_col is not None
                     else _sigma(u_spec, value, where))
            rows.append({"cond": (_number(d[c_col], fpath, line, c_col, "the condition"),),
                         "observable": item["observable"], "value": value, "sigma": sigma})
        if c_col in file_units:
            units[cond_name or "condition"] = file_units[c_col]
        if v_col in file_units:
            units[item["observable"]] = file_units[v_col]
    if not rows:
        raise InputFileError(f"{path}: no data rows (a 'files' list of {{path, observable, uncertainty}} is needed)")
    return Data([cond_name or "condition"], rows, path, units)


def read_data(path, model=None):
    """Measured data from a CSV file (long or wide layout) or a JSON data spec;
    `model` (optional) names the condition columns of a wide CSV."""
    if not os.path.exists(path):
        raise InputFileError(f"data file '{path}' not found")
    if path.endswith(".json"):
        return read_data_spec(path)
    return read_csv(path, list(model.conditions) if model is not None else None)


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
        # the heap-angle extractor's settings, defaults filled in (None: not used)
        self.heap = None
        if "heap_angle" in ex:
            heap = ex["heap_angle"]
            if not isinstance(heap, dict) or "file" not in heap:
                raise InputFileError(f"{path}: extract: 'heap_angle' needs a 'file' (the dump of the final "
                                     "positions: id x y z radius)")
            self.heap = {"file": heap["file"], "key": heap.get("key", "repose_deg"),
                         "layout": heap.get("layout", "axisymmetric"), "bins": heap.get("bins", 16),
                         "central": heap.get("central", [0.25, 0.75])}
            if self.heap["layout"] not in ("axisymmetric", "cell"):
                raise InputFileError(f"{path}: extract: heap_angle 'layout' is '{self.heap['layout']}'; use "
                                     "'axisymmetric' (a conical heap) or 'cell' (a heap against the low-x wall)")
            if not (isinstance(self.heap["bins"], int) and self.heap["bins"] >= 4):
                raise InputFileError(f"{path}: extract: heap_angle 'bins' must be an integer of at least 4")
            cen = self.heap["central"]
            if not (isinstance(cen, list) and len(cen) == 2 and 0 <= cen[0] < cen[1] <= 1):
                raise InputFileError(f"{path}: extract: heap_angle 'central' must be two fractions [lo, hi] "
                                     "with 0 <= lo < hi <= 1")
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
