"""Process-wide settings that decide speed on a small shared machine: one BLAS thread, and a heap that
keeps freed memory.

One BLAS thread unless the user says otherwise.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

import ctypes
import ctypes.util
import os
import sys

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD, _M_MMAP_MAX, _M_ARENA_MAX = -1, -3, -4, -8
_HEAP_KEPT_BYTES = 32 * 1024 * 1024  # glibc's largest allowed mmap threshold on 64-bit
_HEAP_TRIMMED_AT_LEAST = 1024 * 1024 * 1024  # freed memory at the heap's top kept up to 1 GiB at least
_MALLOPT_LARGEST = 2**31 - 1  # mallopt's value is a C int
_HEAP_VARIABLES = ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_MAX_", "MALLOC_ARENA_MAX")


def heap_kept_bytes() -> int:
    """Freed memory at the top of the heap kept for reuse: 2 GiB (mallopt takes a C int), or a quarter of the
    physical memory where that is less, but at least 1 GiB."""
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError):  # no sysconf names: the floor
        physical = 0
    return max(_HEAP_TRIMMED_AT_LEAST, min(physical // 4, _MALLOPT_LARGEST))


def keep_heap() -> None:
    """glibc's heap keeps freed memory (the module's second paragraph); an explicit MALLOC_* variable is kept."""
    if not sys.platform.startswith("linux") or any(v in os.environ for v in _HEAP_VARIABLES):
        return
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(_M_MMAP_THRESHOLD, _HEAP_KEPT_BYTES)
        libc.mallopt(_M_TRIM_THRESHOLD, heap_kept_bytes())
        libc.mallopt(_M_MMAP_MAX, 0)
        libc.mallopt(_M_ARENA_MAX, 1)
    except (OSError, AttributeError):  # not glibc (musl, ...): nothing to tune
        return


_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")


def limit_blas_threads() -> None:
    """One BLAS thread unless the environment names a count (the module's first paragraph)."""
    if any(v in os.environ for v in _VARIABLES):
        return
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    os.environ["MKL_NUM_THREADS"] = "1"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - a declared dependency
        return
    threadpool_limits(1, user_api="blas")


_WIDE_VECTORS = "--xla_cpu_prefer_vector_width=512"


def has_avx512() -> bool:
    """Whether the CPU has AVX-512 (from /proc/cpuinfo; False elsewhere)."""
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            return any(line.startswith("flags") and " avx512f" in line for line in cpuinfo)
    except OSError:  # not Linux: XLA's default
        return False


def prefer_wide_vectors() -> None:
    """512-bit vectors for XLA on an AVX-512 CPU, unless XLA_FLAGS already names the option."""
    flags = os.environ.get("XLA_FLAGS", "")
    if "xla_cpu_prefer_vector_width" in flags or not has_avx512():
        return
    os.environ["XLA_FLAGS"] = f"{flags} {_WIDE_VECTORS}".strip()


_ASYNC_DISPATCH = "JAX_CPU_ENABLE_ASYNC_DISPATCH"


def inline_small_calls() -> None:
    """Compiled programs run on the calling thread from now on, for a process whose calls are small (an
    inversion); effective only before JAX's first computation, a no-op after it or with an explicit
    JAX_CPU_ENABLE_ASYNC_DISPATCH."""
    if _ASYNC_DISPATCH in os.environ:
        return
    import jax

    jax.config.update("jax_cpu_enable_async_dispatch", False)


def configure_process(small_calls: bool = False) -> None:
    """Every process-wide setting of this module, in one call, for the processes that opt in (the command line,
    batch workers, benchmarks, the test suite): one BLAS thread, the heap kept, JAX in double precision with wide
    vectors and its compiled programs kept on disk, and with ``small_calls`` compiled programs run on the calling
    thread. ``import spacepol`` calls none of them; a library user who wants the same speed calls this first."""
    limit_blas_threads()
    keep_heap()
    configure_jax()
    if small_calls:
        inline_small_calls()
    _CONFIGURED.append(small_calls)


_CONFIGURED: list[bool] = []  # the calls of configure_process in this process


def configured() -> bool | None:
    """The ``small_calls`` of this process's last ``configure_process`` call, None where it made none (worker
    processes it starts make the same call)."""
    return _CONFIGURED[-1] if _CONFIGURED else None


def ensure_double_precision() -> None:
    """JAX in double precision, turned on where spacepol first builds a model or a compiled program (not at import):
    the forward model's polarization near the specular peak and nearly index-matched Fresnel reflectances are wrong
    in float32, which is JAX's default. A no-op once it is on."""
    import jax

    if not jax.config.jax_enable_x64:
        jax.config.update("jax_enable_x64", True)


def compilation_cache_folder() -> str:
    """Where compiled programs are kept: $SPACEPOL_CACHE_DIR, else $XDG_CACHE_HOME/spacepol/jax or
    ~/.cache/spacepol/jax; "" where SPACEPOL_CACHE_DIR="" turns the cache off."""
    folder = os.environ.get("SPACEPOL_CACHE_DIR")
    if folder is None:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        folder = os.path.join(base, "spacepol", "jax")
    return folder


def configure_jax() -> None:
    """Wide vectors where the CPU has them, double precision, and compiled programs kept on disk."""
    prefer_wide_vectors()  # before JAX creates its CPU backend, which reads XLA_FLAGS once
    import jax

    jax.config.update("jax_enable_x64", True)
    folder = compilation_cache_folder()
    if not folder:
        return
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return
    if not os.access(folder, os.W_OK):
        return
    jax.config.update("jax_compilation_cache_dir", folder)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)


def spawned_pool(workers: int, initializer=None, initargs: tuple = (), **options):
    """A ``ProcessPoolExecutor`` of ``workers`` processes started by spawn, never fork: a forked child of a process
    that has started JAX's thread pool can inherit a lock held by a thread it does not have and wait on it forever.
    Its workers end when the process that started them is gone (``exit_with_parent``), then run ``initializer``
    (with ``initargs``) where given. ``options``: the executor's other arguments."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_start_worker, initargs=(os.getpid(), initializer, initargs), **options)


def _start_worker(parent: int, initializer, initargs: tuple) -> None:
    exit_with_parent(parent)
    if initializer is not None:
        initializer(*initargs)


def exit_with_parent(parent: int, every_s: float = 1.0) -> None:
    """This process ends when the one that started it (``parent``, its pid as the parent saw it: a parent killed
    while this process was still starting is gone already when it looks) is gone: a pool's workers outlive a parent
    killed by a signal it cannot handle (SIGTERM, SIGKILL) and would go on computing with nobody to read them."""
    import threading
    import time

    def watch():
        while os.getppid() == parent:
            time.sleep(every_s)
        os._exit(1)

    threading.Thread(target=watch, name="spacepol-parent-watch", daemon=True).start()
