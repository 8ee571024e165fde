"""The kernel warm-up (`continuum.numerics.kernel_warmup`) compiles what a contact uses, and its locks exclude."""
import logging

import pytest

from continuum.numerics import kernel_warmup as kw
from continuum.numerics.compiled_contact import warm_up

pytestmark = pytest.mark.skipif(kw.fcntl is None, reason="the warm-up needs fcntl (not on Windows)")


def test_the_laws_part_compiles_the_specialisations_the_contact_kernel_uses():
    """After a contact ran (warm_up: compiled or loaded), every (dispatcher, argument types) of the laws' part is one
    of the specialisations the dispatcher holds in numba's cache index (what the contact kernel compiled for it,
    whether this process compiled it or loaded the kernel): a warm-up with other types, or of a function the kernel
    inlines, would compile code no contact loads."""
    warm_up()
    for dispatcher, sig in kw.law_part():
        cached = [tuple(key[0]) for key in dispatcher._cache._cache_file._load_index()]
        assert tuple(sig) in cached, dispatcher.py_func.__qualname__
    assert kw.is_warm()


def test_a_function_lock_excludes_another_holder_and_is_reentrant(tmp_path, monkeypatch, caplog):
    """A second holder (another open file: as another process) waits for the lock, and after LOCK_WAIT_S goes on
    with a warning; the holder itself may take it again (a recursive compile)."""
    monkeypatch.setattr(kw, "LOCK_WAIT_S", 0.2)
    first, second = kw._FunctionLocks(tmp_path), kw._FunctionLocks(tmp_path)
    with first.hold("m.f"), first.hold("m.f"):
        with caplog.at_level(logging.WARNING, logger=kw.__name__):
            with second.hold("m.f"):
                pass
        assert "compiling it here too" in caplog.text
        caplog.clear()
        with second.hold("m.g"):            # another function: no wait
            pass
        assert caplog.text == ""
    with second.hold("m.f"):                # released: taken at once
        pass
    assert caplog.text == ""
