"""Shared fixtures: the Table I scenario of the paper (stage, controller, dynamic link, loop)."""

from __future__ import annotations

import signal

import pytest

from motionhyst.controllers.leadlag import LeadLagLowpass
from motionhyst.controllers.loop import Loop
from motionhyst.core.compiled import quiet_compilation
from motionhyst.hysteresis.jenkins import Jenkins
from motionhyst.plants.two_mass import TwoMassStage

# the tests check the commands' stderr: no notice of the first compilation in this session
# (tests/test_startup.py checks the notice in fresh processes)
quiet_compilation()

# a suite started in the background by a non-interactive shell (`make test &`) inherits SIGINT
# ignored, and so would every command the tests start: Python then installs no Ctrl-C handler
# in them and the tests that send a Ctrl-C would see the command run on (exit 0); a terminal's
# Ctrl-C reaches a command whose SIGINT is at its default, so the suite restores that
signal.signal(signal.SIGINT, signal.default_int_handler)

# Table I of the paper
M1, M2, B, K_STAGE = 5.0, 17.5, 90.0, 7.4e7
K_LINK, FC_LINK = 20.0, 0.05
K_GAIN, F1, F2, FLP, BETA = 6.2e6, 60.0, 240.0, 700.0, 0.6
A_REF = 0.01  # reference amplitude of section V [m]


@pytest.fixture
def stage() -> TwoMassStage:
    return TwoMassStage(m1=M1, m2=M2, b=B, k=K_STAGE)


@pytest.fixture
def controller() -> LeadLagLowpass:
    return LeadLagLowpass(K=K_GAIN, f1=F1, f2=F2, flp=FLP, beta=BETA)


@pytest.fixture
def link() -> Jenkins:
    return Jenkins(k=K_LINK, fc=FC_LINK)


@pytest.fixture
def loop(stage, controller, link) -> Loop:
    return Loop(stage, controller, link)
