"""Shared fixtures of the Python tests (tests/python/)."""

import pathlib

import pytest

import terrasynth

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def db() -> terrasynth.Database:
    # Builds the embedded database into the cache once (workers of the Dask
    # test then load it from there).
    return terrasynth.Database.default()


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    return ROOT
