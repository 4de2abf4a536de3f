"""Interrupts: the first stops, the later ones are counted; deferred ones wait for the block's end."""

from __future__ import annotations

import os
import signal
import sys

import pytest

from freefloat.app.signals import (
    cut_by_interrupt,
    imported_whole,
    signals_deferred,
    signals_held,
    signals_raise_keyboard_interrupt,
    stop_once,
)


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


def test_an_import_cut_by_sigterm_finishes_before_the_interrupt(tmp_path, monkeypatch):
    """A SIGTERM arriving while imported_whole imports a module lets the import finish (the
    module is whole in sys.modules), then raises KeyboardInterrupt naming it."""
    (tmp_path / "signalled_module.py").write_text(
        "import os, signal\nos.kill(os.getpid(), signal.SIGTERM)\nAFTER_THE_SIGNAL = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "signalled_module", raising=False)
    with signals_raise_keyboard_interrupt(), pytest.raises(KeyboardInterrupt, match="SIGTERM"):
        imported_whole("signalled_module")
    assert sys.modules["signalled_module"].AFTER_THE_SIGNAL


def test_an_import_error_raised_from_an_interrupt_is_told_as_the_interrupt():
    """cut_by_interrupt finds the KeyboardInterrupt under an ImportError (what a compiled
    module's initialisation raises when an interrupt cuts it), and nothing under a plain one."""
    try:
        try:
            raise KeyboardInterrupt("SIGTERM")
        except KeyboardInterrupt as stop:
            raise ImportError("initialization failed") from stop
    except ImportError as exc:
        assert str(cut_by_interrupt(exc)) == "SIGTERM"
    assert cut_by_interrupt(ImportError("no module named 'mujoco'")) is None
