"""``batch --dask``: the batch's chunks synthesized on a Dask cluster (dask.distributed, the command line's
optional extra ``dask``; imported only here and only when asked, never inside Blender).

The client (this process) reads the CSV, sends each chunk's rows to the cluster (one task per reference set in
the chunk, ``core.synthesis.batch.synthesize_chunk``: the workers import the core only), keeps at most ``WINDOW``
chunks in flight and takes their results back in the CSV's order, writing every file itself, so each file is
written once, atomically, where the command runs, and memory stays flat in the row count. A task that fails is
retried (``RETRIES``); a chunk that still fails is reported row by row and the others go on. Chunks are
synthesized exactly as in a serial run (batched and one-at-a-time synthesis give the same bits), so the files are
the same.
"""

import logging
import re

from .output import UsageError, one_line

RETRIES = 2  # more attempts of a failed chunk (a worker lost, a transient error)
WINDOW = 8  # chunks in flight at once: the workers kept busy, the results waiting to be written bounded
CONNECT_TIMEOUT = "10s"
_LOCAL = re.compile(r"local:(\d+)")
MAX_LOCAL_WORKERS = 256


def connect(address):
    """A Cluster for ``--dask ADDRESS`` (tcp://HOST:PORT, or local:N); UsageError in one line if it cannot be had."""
    text = address.strip()
    local = _LOCAL.fullmatch(text)
    if not local and not re.fullmatch(r"(tcp|tls)://\S+", text):
        raise UsageError(
            f"--dask takes a scheduler address tcp://HOST:PORT or local:N (N workers here), got {address!r}"
        )
    if local and not 1 <= int(local.group(1)) <= MAX_LOCAL_WORKERS:
        raise UsageError(f"--dask local:N takes 1 to {MAX_LOCAL_WORKERS} workers, got {local.group(1)}")
    try:
        import distributed
    except ImportError:
        raise UsageError("--dask needs dask.distributed: pip install 'ellimann[dask]' (or dask[distributed])") from None
    quiet = logging.ERROR
    for name in ("distributed", "tornado", "asyncio"):
        logging.getLogger(name).setLevel(quiet)
    if local:
        try:
            cluster = distributed.LocalCluster(
                n_workers=int(local.group(1)),
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=quiet,
            )
        except Exception as error:  # noqa: BLE001 - any failure to start workers is the user's one line
            raise UsageError(f"--dask {address}: cannot start a local cluster: {one_line(error)}") from None
        return Cluster(distributed.Client(cluster), cluster)
    try:
        client = distributed.Client(text, timeout=CONNECT_TIMEOUT)
    except Exception as error:  # noqa: BLE001 - OSError, TimeoutError, CommClosedError...: one line, nothing written
        raise UsageError(
            f"--dask {address}: cannot reach the scheduler: {one_line(error) or type(error).__name__}"
        ) from None
    return Cluster(client, None)


class Cluster:
    """A connected client (and the local cluster it started, if any)."""

    window = WINDOW

    def __init__(self, client, local):
        self.client, self.local = client, local
        self.shared = {}  # each reference set is sent once, not with every task

    def submit(self, groups, options):
        """Send a chunk's groups of rows (``[(reference set, requests (k, 5), extras)]``) to the cluster; what
        :meth:`results` takes."""
        from ..core.synthesis.batch import synthesize_chunk

        futures = []
        for reference, requests, extras in groups:
            if id(reference) not in self.shared:
                self.shared[id(reference)] = self.client.scatter(reference, broadcast=True)
            futures.append(
                self.client.submit(
                    synthesize_chunk, self.shared[id(reference)], requests, options, extras, retries=RETRIES, pure=False
                )
            )
        return groups, options, futures

    def results(self, submitted):
        """The SynthesizedBatch of each group :meth:`submit` sent, waiting for them; a group that failed every
        attempt comes back with every row's error set."""
        from ..core.synthesis.batch import failed_chunk

        groups, options, futures = submitted
        results = []
        for (reference, requests, _), future in zip(groups, futures):
            try:
                result = future.result()
            except Exception as error:  # noqa: BLE001 - the chunk's rows are reported, the other chunks go on
                reason = f"its chunk failed on the Dask cluster after {RETRIES + 1} attempts: {one_line(error)}"
                result = failed_chunk(reference, requests, [reason] * len(requests), options.mode)
            future.release()
            results.append(result)
        return results

    def close(self):
        self.client.close()
        if self.local is not None:
            self.local.close()
