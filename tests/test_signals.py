"""Interrupts: the first stops, the later ones are counted; deferred ones wait for the block's end."""

from __future__ import annotations

import os
import signal

import pytest

from freefloat.app.signals import signals_deferred, signals_held, stop_once


def test_only_the_first_interrupt_raises():
    """Inside stop_once, the first SIGINT raises KeyboardInterrupt and a second only counts."""
    with stop_once() as interrupts:
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            signal.sigtimedwait([], 0.01) if hasattr(signal, "sigtimedwait") else None
        os.kill(os.getpid(), signal.SIGTERM)
    assert interrupts.count == 2


def test_after_defer_no_interrupt_raises():
    """Once deferred, even a first interrupt only counts."""
    with stop_once() as interrupts:
        interrupts.defer()
        os.kill(os.getpid(), signal.SIGINT)
    assert interrupts.count == 1


def test_deferred_signals_set_the_event():
    """Inside signals_deferred, Ctrl-C and SIGTERM set the event and raise nothing."""
    with signals_deferred() as received:
        os.kill(os.getpid(), signal.SIGINT)
        os.kill(os.getpid(), signal.SIGTERM)
    assert received.is_set()


def test_held_signals_raise_when_the_block_ends():
    """Inside signals_held, SIGTERM then SIGINT let the block finish; leaving it raises
    KeyboardInterrupt naming the first."""
    finished = False
    with pytest.raises(KeyboardInterrupt, match="SIGTERM"):
        with signals_held():
            os.kill(os.getpid(), signal.SIGTERM)
            os.kill(os.getpid(), signal.SIGINT)
            finished = True
    assert finished
