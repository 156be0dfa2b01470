"""``batch --dask``: the batch's chunks synthesized on a Dask cluster (dask.distributed, the command line's
optional extra ``dask``; imported only here and only when asked, never inside Blender).

The client (this process) reads the CSV, sends each chunk of requests to the cluster as one task, and writes
every file itself as the chunks come back, so each file is written once, atomically, where the command runs.
A task that fails is retried (``RETRIES``); a chunk that still fails is reported row by row and the others go
on. Chunks are synthesized exactly as in a serial run (``batch.synthesize_chunk``: batched and one-at-a-time
synthesis give the same bits), so the files are the same.
"""

import logging
import re

from .output import UsageError, one_line

RETRIES = 2  # more attempts of a failed chunk (a worker lost, a transient error)
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

    def __init__(self, client, local):
        self.client, self.local = client, local

    def map(self, references, requests, options):
        """Synthesize each chunk of ``requests`` (a list of lists of 5 values) from its reference set
        (``references``, one per chunk) on the cluster: yields (chunk index, ChunkResult) as chunks finish; a
        chunk that failed every attempt comes back with every row's error set."""
        from distributed import as_completed

        from ..core.synthesis.batch import ChunkResult, synthesize_chunk

        shared = {}  # each reference set is sent once, not with every task
        for reference in references:
            if id(reference) not in shared:
                shared[id(reference)] = self.client.scatter(reference, broadcast=True)
        futures = [
            self.client.submit(synthesize_chunk, shared[id(reference)], chunk, options, retries=RETRIES, pure=False)
            for reference, chunk in zip(references, requests)
        ]
        index = {future.key: i for i, future in enumerate(futures)}
        for future in as_completed(futures):
            i = index[future.key]
            try:
                result = future.result()
            except Exception as error:  # noqa: BLE001 - the chunk's rows are reported, the other chunks go on
                reason = f"its chunk failed on the Dask cluster after {RETRIES + 1} attempts: {one_line(error)}"
                result = ChunkResult(None, [reason] * len(requests[i]), **dict.fromkeys(ChunkResult.FIELDS))
            future.release()
            yield i, result

    def close(self):
        self.client.close()
        if self.local is not None:
            self.local.close()
