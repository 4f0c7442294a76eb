"""A throwaway single-node Slurm cluster on this machine, for ``tests/test_slurm.py``.

:class:`LocalSlurm` starts the three daemons itself (no systemd): ``munged`` as the
``munge`` user with a fresh key and a private socket, then ``slurmctld`` and
``slurmd`` as root, all in the foreground (``-F`` / ``-D``) so that the PIDs it
holds are the daemons' own. It stops them by those PIDs (SIGTERM, then SIGKILL after
a bounded wait), together with the helper processes they forked. Every wait is bounded.

Where things live:

* state, spool, logs, munge key and socket: a private directory under ``/tmp``
  (mode 0755, so that the ``munge`` user can reach its socket), removed on stop;
* the configuration: ``/etc/slurm/slurm.conf``, marked as ours and removed on stop.
  It has to be at the default path: the Slurm executor plugin runs each rule through
  ``srun`` inside the batch job with every ``SLURM_*`` variable removed from the
  environment (``SLURM_CONF`` too), so a configuration anywhere else is not found.
  A configuration there that is not ours is never touched: the cluster is then
  reported unavailable.

There is no ``slurmdbd``: ``AccountingStorageType=accounting_storage/none``, so
``sacct`` answers "accounting storage is disabled". Job states come from
``squeue``, which keeps finished jobs for ``MinJobAge`` (set to an hour here) and
which the profile ``workflow/profiles/slurm`` selects (``slurm-status-command: squeue``).

One cluster per machine at a time: :meth:`LocalSlurm.start` takes an exclusive lock
(``/run/lock/netrepro-slurm-test.lock``) and waits for it, bounded.

Run by hand (as root) for a cluster to try things on; Ctrl-C stops it::

    python tests/slurm/cluster.py
"""

from __future__ import annotations

import fcntl
import os
import pwd
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["SlurmUnavailable", "LocalSlurm", "unavailable_reason", "PARTITION"]

SLURM_CONF = Path("/etc/slurm/slurm.conf")
MARKER = "# netrepro test cluster: written by tests/slurm/cluster.py, removed when it stops"
PARTITION = "netrepro"
LOCK_FILE = Path("/run/lock/netrepro-slurm-test.lock")
PID_FILE = Path("/run/lock/netrepro-slurm-test.pids")  # daemons of a cluster whose owner was killed
DAEMONS = ("munged", "slurmctld", "slurmd")
CLIENTS = ("sbatch", "srun", "squeue", "scontrol", "scancel", "sinfo", "munge", "unmunge")
PACKAGES = "munge slurmctld slurmd slurm-client"


class SlurmUnavailable(RuntimeError):
    """Slurm cannot be started on this machine; the message says why."""


def _which(name):
    return shutil.which(name) or next(
        (str(p) for p in (Path("/usr/sbin") / name, Path("/sbin") / name) if p.is_file()), None
    )


def unavailable_reason() -> str | None:
    """Why a local cluster cannot be started here, or None when it can (checks only, starts nothing)."""
    if os.environ.get("NETREPRO_SKIP_SLURM"):
        return "NETREPRO_SKIP_SLURM is set"
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return "starting munged, slurmctld and slurmd needs root"
    missing = [name for name in DAEMONS + CLIENTS if _which(name) is None]
    if missing:
        return (f"Slurm commands not found: {', '.join(missing)} "
                f"(Debian packages {PACKAGES}; CI installs them with .ci/setup.d/20-slurm.sh)")
    try:
        pwd.getpwnam("munge")
    except KeyError:
        return "no 'munge' user (the Debian package munge creates it)"
    if SLURM_CONF.exists() and MARKER not in SLURM_CONF.read_text(errors="replace"):
        return f"{SLURM_CONF} exists and is not ours: a real Slurm is configured here; not touching it"
    return None


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _run(cmd, timeout=20, env=None, check=False):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env, check=check)


def _wait_for(predicate, timeout, what, interval=0.5):
    """Poll ``predicate`` until it returns a true value, at most ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    last_error = None
    while time.monotonic() < deadline:
        try:
            value = predicate()
            if value:
                return value
        except (subprocess.SubprocessError, OSError) as exc:
            last_error = exc
        time.sleep(interval)
    raise TimeoutError(f"timed out after {timeout} s waiting for {what}" + (f" ({last_error})" if last_error else ""))


def _children(pid: int) -> list[int]:
    """PIDs of the descendants of ``pid`` (from /proc), deepest last."""
    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            parents.setdefault(int(fields[1]), []).append(int(stat.parent.name))
        except (OSError, IndexError, ValueError):
            continue
    found, todo = [], [pid]
    while todo:
        for child in parents.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:  # a zombie that its parent has not reaped yet counts as gone
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def _terminate(pids, grace=15.0):
    """SIGTERM the PIDs, wait at most ``grace`` seconds, SIGKILL whatever is left."""
    pids = [p for p in pids if _alive(p)]
    for pid in pids:
        try:
            os.kill(pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline and any(_alive(p) for p in pids):
        time.sleep(0.2)
    for pid in pids:
        if _alive(pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def _stop_stale_daemons():
    """Stop the daemons a killed test session left behind (PIDs recorded in PID_FILE, names checked)."""
    if not PID_FILE.exists():
        return
    stale, dirs = [], []
    for line in PID_FILE.read_text().splitlines():
        name, _, pid = line.partition(" ")
        if name == "dir" and pid.startswith("/tmp/netrepro-slurm-"):
            dirs.append(Path(pid))
        elif name in DAEMONS and pid.isdigit() and _alive(int(pid)) and name in _cmdline(int(pid)):
            stale.append(int(pid))
            stale.extend(_children(int(pid)))
    _terminate(stale)
    for path in dirs:
        shutil.rmtree(path, ignore_errors=True)
    PID_FILE.unlink()


class LocalSlurm:
    """A single-node Slurm cluster (controller and compute node on this host).

    Parameters
    ----------
    cpus, memory_mb
        What the node offers. More than the hardware is fine (``config_overrides``;
        nothing enforces memory without cgroups): shards then run side by side.
    start_timeout
        Seconds to wait for each daemon to come up.
    lock_timeout
        Seconds to wait for another local cluster (another test session) to finish.
    default_partition
        Whether the partition ``netrepro`` is the default one. When it is not, a job
        is accepted only if it names the partition (``sbatch -p netrepro``).
    """

    def __init__(self, cpus: int | None = None, memory_mb: int | None = None, start_timeout: float = 60,
                 lock_timeout: float = 900, default_partition: bool = True):
        self.cpus = cpus or max(os.cpu_count() or 1, 4)
        self.memory_mb = memory_mb or 16000
        self.start_timeout = start_timeout
        self.lock_timeout = lock_timeout
        self.default_partition = default_partition
        self.host = socket.gethostname().split(".")[0]
        self.dir: Path | None = None
        self.procs: dict[str, subprocess.Popen] = {}
        self._helpers: set[int] = set()
        self._lock = None
        self._wrote_conf = False

    # ---- paths and environment -------------------------------------------------------------
    @property
    def munge_socket(self) -> Path:
        return self.dir / "munge" / "munge.socket"

    def client_env(self, base=None) -> dict:
        """An environment for Slurm clients and Snakemake: no inherited SLURM_/SBATCH_/SRUN_ settings."""
        env = dict(os.environ if base is None else base)
        for key in list(env):
            if key.startswith(("SLURM_", "SBATCH_", "SRUN_", "SALLOC_")):
                del env[key]
        return env

    def log_tail(self, lines: int = 30) -> str:
        """The last lines of every daemon log, for error messages."""
        if self.dir is None:
            return ""
        out = []
        for log in sorted((self.dir / "log").glob("*")) + [self.dir / "munge" / "munged.log"]:
            if log.is_file():
                text = log.read_text(errors="replace").splitlines()[-lines:]
                out.append(f"--- {log.name}\n" + "\n".join(text))
        return "\n".join(out)

    # ---- start -----------------------------------------------------------------------------
    def _acquire_lock(self):
        LOCK_FILE.parent.mkdir(parents=True, exist_ok=True)
        self._lock = open(LOCK_FILE, "w")
        deadline = time.monotonic() + self.lock_timeout
        while True:
            try:
                fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return
            except BlockingIOError:
                if time.monotonic() > deadline:
                    self._lock.close()
                    self._lock = None
                    raise SlurmUnavailable(f"another local test cluster holds {LOCK_FILE} "
                                           f"for more than {self.lock_timeout:.0f} s")
                time.sleep(2)

    def _spawn(self, name, cmd, **kwargs):
        log = open(self.dir / "log" / f"{name}.out", "w")
        self.procs[name] = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                            start_new_session=True, env=self.client_env(), **kwargs)
        log.close()
        with open(PID_FILE, "a") as pids:
            pids.write(f"{name} {self.procs[name].pid}\n")

    def _check_running(self, name):
        proc = self.procs[name]
        if proc.poll() is not None:
            raise SlurmUnavailable(f"{name} exited with status {proc.returncode}\n{self.log_tail()}")

    def _write_config(self):
        d = self.dir
        ctld_port, slurmd_port = _free_port(), _free_port()
        conf = f"""{MARKER}
ClusterName=netrepro
SlurmctldHost={self.host}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={self.munge_socket}
CredType=cred/munge
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/log/slurmctld.log
SlurmdLogFile={d}/log/slurmd.log
MailProg=/bin/true
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
# no slurmdbd: job states come from squeue, which keeps finished jobs for MinJobAge seconds
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MinJobAge=3600
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
SlurmdParameters=config_overrides
NodeName={self.host} NodeAddr=127.0.0.1 CPUs={self.cpus} RealMemory={self.memory_mb} State=UNKNOWN
PartitionName={PARTITION} Nodes={self.host} Default={"YES" if self.default_partition else "NO"} MaxTime=INFINITE State=UP
"""
        SLURM_CONF.parent.mkdir(parents=True, exist_ok=True)
        tmp = SLURM_CONF.with_name(SLURM_CONF.name + ".netrepro-tmp")
        tmp.write_text(conf)
        os.replace(tmp, SLURM_CONF)
        self._wrote_conf = True

    def _start_munge(self):
        munge_dir = self.dir / "munge"
        munge_dir.mkdir()
        user = pwd.getpwnam("munge")
        key = munge_dir / "munge.key"
        key.write_bytes(os.urandom(1024))
        for path, mode in ((munge_dir, 0o755), (key, 0o400)):
            os.chown(path, user.pw_uid, user.pw_gid)
            os.chmod(path, mode)
        self._spawn("munged", [_which("munged"), "-F", f"--socket={self.munge_socket}", f"--key-file={key}",
                               f"--pid-file={munge_dir / 'munged.pid'}", f"--log-file={munge_dir / 'munged.log'}",
                               f"--seed-file={munge_dir / 'munged.seed'}"],
                    user=user.pw_uid, group=user.pw_gid, extra_groups=[])

        def credential_roundtrip():
            self._check_running("munged")
            if not self.munge_socket.exists():
                return False
            cred = _run(["munge", "-n", "-S", str(self.munge_socket)], timeout=10)
            if cred.returncode != 0:
                return False
            decoded = subprocess.run(["unmunge", "-S", str(self.munge_socket)], input=cred.stdout,
                                     capture_output=True, text=True, timeout=10)
            return decoded.returncode == 0

        _wait_for(credential_roundtrip, self.start_timeout, "munged to issue and decode a credential")

    def _node_state(self) -> str:
        out = _run(["sinfo", "-h", "-N", "-n", self.host, "-o", "%t"], env=self.client_env(), timeout=10)
        return out.stdout.strip() if out.returncode == 0 else ""

    def start(self) -> "LocalSlurm":
        """Start munged, slurmctld and slurmd; return once the node accepts jobs."""
        reason = unavailable_reason()
        if reason:
            raise SlurmUnavailable(reason)
        self._acquire_lock()
        try:
            _stop_stale_daemons()
            self.dir = Path(tempfile.mkdtemp(prefix="netrepro-slurm-", dir="/tmp"))
            os.chmod(self.dir, 0o755)
            PID_FILE.write_text(f"dir {self.dir}\n")
            for sub in ("state", "spool", "log"):
                (self.dir / sub).mkdir()
            self._start_munge()
            self._write_config()
            self._spawn("slurmctld", [_which("slurmctld"), "-D", "-f", str(SLURM_CONF)])

            def controller_up():
                self._check_running("slurmctld")
                return _run(["scontrol", "ping"], env=self.client_env(), timeout=10).stdout.count("UP") > 0

            _wait_for(controller_up, self.start_timeout, "slurmctld to answer 'scontrol ping'")
            self._spawn("slurmd", [_which("slurmd"), "-D", "-N", self.host, "-f", str(SLURM_CONF)])

            def node_idle():
                self._check_running("slurmd")
                state = self._node_state()
                if state.startswith(("down", "drain")):
                    _run(["scontrol", "update", f"nodename={self.host}", "state=resume"], env=self.client_env())
                return state.rstrip("*~#!%$@^-") == "idle"

            _wait_for(node_idle, self.start_timeout, f"node {self.host} to become idle")
        except BaseException as exc:
            logs = self.log_tail()
            self.stop()
            if isinstance(exc, (TimeoutError, subprocess.SubprocessError, OSError)):
                raise SlurmUnavailable(f"{exc}\n{logs}") from exc
            raise
        return self

    # ---- use ---------------------------------------------------------------------------------
    def jobs(self, states: str = "all", fields: str = "%i|%j|%T") -> list[tuple[str, ...]]:
        """The jobs the controller knows (finished ones for MinJobAge), by default as
        ``(job id, job name, state)``; ``fields`` is a ``squeue -o`` format joined by ``|``."""
        out = _run(["squeue", "-h", "-t", states, "-o", fields], env=self.client_env(), timeout=20, check=True)
        return [tuple(line.split("|")) for line in out.stdout.splitlines() if line.strip()]

    # ---- stop --------------------------------------------------------------------------------
    def stop(self):
        """Cancel leftover jobs, stop the daemons by PID, remove our configuration and directory."""
        try:
            if "slurmctld" in self.procs and self.procs["slurmctld"].poll() is None:
                try:
                    _run(["scancel", "-p", PARTITION], env=self.client_env(), timeout=20)
                    _wait_for(lambda: not self.jobs("PENDING,RUNNING,COMPLETING,CONFIGURING,SUSPENDED"), 30,
                              "cancelled jobs to end")
                except (TimeoutError, subprocess.SubprocessError, OSError):
                    pass
            for name in ("slurmd", "slurmctld", "munged"):
                proc = self.procs.get(name)
                if proc is None:
                    continue
                helpers = _children(proc.pid)  # slurmctld's slurmscriptd, slurmd's slurmstepd
                _terminate([proc.pid])
                try:
                    proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    pass
                _terminate(helpers, grace=5)
            self.procs.clear()
            PID_FILE.unlink(missing_ok=True)
        finally:
            if self._wrote_conf and SLURM_CONF.exists() and MARKER in SLURM_CONF.read_text(errors="replace"):
                SLURM_CONF.unlink()
            self._wrote_conf = False
            if self.dir is not None and not os.environ.get("NETREPRO_KEEP_SLURM_DIR"):
                shutil.rmtree(self.dir, ignore_errors=True)
            if self._lock is not None:
                fcntl.flock(self._lock, fcntl.LOCK_UN)
                self._lock.close()
                self._lock = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
        return False


def main() -> int:
    cluster = LocalSlurm()
    try:
        cluster.start()
    except SlurmUnavailable as exc:
        print(f"cannot start a local Slurm cluster: {exc}", file=sys.stderr)
        return 1
    stop = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.append(True))
    print(f"Slurm is up: node {cluster.host}, partition {PARTITION}, config {SLURM_CONF}, files in {cluster.dir}")
    print("Ctrl-C stops it.")
    try:
        while not stop:
            time.sleep(0.5)
    finally:
        cluster.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
