"""foreign.contained: foreign code's exceptions are kept, real stop signals go on (issue 32,
item 8)."""

from __future__ import annotations

import os
import signal
import time

import pytest

from rrtpso_ompl.foreign import contained, describe_failure, noting_stop_signals


@pytest.mark.parametrize(
    ("exc", "message"),
    [
        (SystemExit(3), "SystemExit: sys.exit(3) was called"),
        (KeyboardInterrupt(), "KeyboardInterrupt"),
        (ValueError("a\nb"), "ValueError: a b"),
        (RuntimeError("x" * 10_000), "RuntimeError: xxx"),
    ],
)
def test_whatever_the_code_raises_is_kept_in_one_bounded_line(exc, message):
    with contained() as box:
        raise exc
    assert box.error is exc and box.message.startswith(message)
    assert "\n" not in box.message and len(box.message) < 400


def test_the_callers_own_errors_pass_through():
    with pytest.raises(MemoryError), contained(passthrough=(MemoryError,)):
        raise MemoryError


def test_a_real_ctrl_c_goes_on_even_when_the_code_swallows_it():
    with pytest.raises(KeyboardInterrupt), contained() as box:
        os.kill(os.getpid(), signal.SIGINT)  # delivered at the next bytecode
        time.sleep(30)  # the handler runs first
    assert box.error is None
    with pytest.raises(KeyboardInterrupt), contained():
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(30)
        except KeyboardInterrupt:
            pass  # swallowed by the plugin
    with pytest.raises(KeyboardInterrupt), contained():
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(30)
        except KeyboardInterrupt:
            raise ValueError("something else") from None


def test_the_previous_handlers_are_back_and_run_for_a_real_signal():
    seen = []

    def handler(signum, frame):
        seen.append(signum)
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, handler)
    try:
        with pytest.raises(KeyboardInterrupt), noting_stop_signals() as watch:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(30)
        assert seen == [signal.SIGTERM] and watch.received == [signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is handler
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGTERM, old)


def test_describe_failure_survives_a_broken_str():
    class Odd(Exception):
        def __str__(self):
            raise RuntimeError

    assert describe_failure(Odd()) == "Odd"
