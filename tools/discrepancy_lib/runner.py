"""Running granary for one set of -var settings and extracting the printed
observables; runs are cached by their settings and executed several at once."""
import concurrent.futures
import os
import subprocess
import tempfile

from . import extractors


class RunError(Exception):
    pass


def fmt(value):
    if isinstance(value, float):
        if value.is_integer() and abs(value) < 1e15:
            return str(int(value))  # integer-valued settings (counts, seeds) as integers
        return f"{value:.12g}"
    return str(value)


def parse_results(text, prefix):
    """Key/value pairs of every line 'PREFIX key value key value ...'."""
    out = {}
    for line in text.splitlines():
        words = line.split()
        if not words or words[0] != prefix:
            continue
        for k in range(1, len(words) - 1, 2):
            try:
                out[words[k]] = float(words[k + 1])
            except ValueError:
                pass
    return out


# Each run is one serial process. Open MPI's singleton start-up probes the
# network and spawns helpers (about 0.5 s); isolated singletons with only the
# self transport start in about 0.05 s. Settings in the environment win;
# other MPI libraries ignore these names.
SERIAL_MPI_ENV = {"OMPI_MCA_ess_singleton_isolated": "1", "OMPI_MCA_btl": "self", "OMPI_MCA_pml": "ob1"}


class Runner:
    def __init__(self, granary, model, jobs=1, verbose=False):
        self.granary = granary
        self.model = model
        self.jobs = max(1, int(jobs))
        self.cache = {}
        self.nruns = 0
        self.verbose = verbose
        self.env = dict(os.environ)
        for k, v in SERIAL_MPI_ENV.items():
            self.env.setdefault(k, v)

    def _run_one(self, settings):
        # A failed MPI start-up (rare, under heavy load) is retried; a failure
        # of the script itself is reported at once.
        for attempt in range(3):
            try:
                return self._run_once(settings)
            except RunError as e:
                if "MPI_Init" not in str(e) and "MPI_INIT" not in str(e) or attempt == 2:
                    raise

    def _run_once(self, settings):
        args = [self.granary, "-in", self.model.script, "-log", "none", "-echo", "none"]
        for k, v in settings:
            args += ["-var", k, v]
        with tempfile.TemporaryDirectory(prefix="discrepancy_") as tmp:
            try:
                proc = subprocess.run(args, cwd=tmp, capture_output=True, text=True, env=self.env,
                                      timeout=self.model.timeout)
            except subprocess.TimeoutExpired:
                raise RunError(f"granary run timed out after {self.model.timeout} s: {' '.join(args)}")
            text = proc.stdout
            if self.model.result_file:
                path = os.path.join(tmp, self.model.result_file)
                if os.path.exists(path):
                    with open(path) as f:
                        text = f.read()
            derived = {}
            heap = self.model.heap
            if heap and proc.returncode == 0:
                path = os.path.join(tmp, heap["file"])
                if not os.path.exists(path):
                    raise RunError(f"the run did not write '{heap['file']}' for heap_angle: {' '.join(args)}")
                angle, _ = extractors.heap_angle(path, tuple(heap["central"]), heap["bins"], heap["layout"])
                derived[heap["key"]] = angle
        if proc.returncode != 0:
            # the end of the output and the whole error stream (a crash's backtrace starts with
            # the frame that failed; cutting it off hides where)
            lines = proc.stdout.strip().splitlines()[-5:] + ["(standard error:)"]
            lines += proc.stderr.strip().splitlines()[-80:]
            raise RunError("granary failed (exit %d): %s\n  %s" % (proc.returncode, " ".join(args),
                                                                   "\n  ".join(lines)))
        res = parse_results(text, self.model.prefix)
        res.update(derived)
        if not res:
            raise RunError(f"no '{self.model.prefix} key value ...' line in the output of: {' '.join(args)}")
        return res

    def run_many(self, settings_list):
        """Results (dicts key -> value) for a list of settings dicts, in order."""
        keys = [tuple(sorted((k, fmt(v)) for k, v in s.items())) for s in settings_list]
        todo = [k for k in dict.fromkeys(keys) if k not in self.cache]
        if todo:
            with concurrent.futures.ThreadPoolExecutor(max_workers=self.jobs) as pool:
                for key, res in zip(todo, pool.map(self._run_one, todo)):
                    self.cache[key] = res
            self.nruns += len(todo)
        return [self.cache[k] for k in keys]
