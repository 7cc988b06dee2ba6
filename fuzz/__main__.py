"""``python -m fuzz [--budget N --seed S] [--in-process] [--quiet]`` (the fuzz command), and
``python -m fuzz worker --seed S --start K --count N``, the worker process the command starts.
The memory check is ``python -m fuzz.memcheck``."""
import os
import signal
import sys

from .runner import _worker, main


def worker(argv) -> int:
    """The worker: its parent reads its stdout and reports. Started by the parent (stdout a
    pipe), it leaves Ctrl-C, which reaches the whole process group, to the parent, and ends
    without a word at its next line once the parent is gone (a closed pipe)."""
    from reactor.cli import ArgumentParser, non_negative_int, positive_int

    p = ArgumentParser(prog="python -m fuzz worker",
                       examples=("python -m fuzz worker --seed 7 --start 140 --count 5",))
    p.add_argument("worker")
    p.add_argument("--seed", default="0")
    p.add_argument("--start", type=non_negative_int, default=0)
    p.add_argument("--count", type=positive_int, default=1)
    a = p.parse_args(argv)
    if not sys.stdout.isatty():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        return _worker(a.seed, a.start, a.count)
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(worker(sys.argv[1:]) if sys.argv[1:2] == ["worker"] else main())
