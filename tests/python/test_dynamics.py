"""saltus.Model and the dynamics kernels from Python: identities between the kernels (τ = M q̈ + h,
ABA inverts RNEA, T = ½ q̇ᵀ M q̇), the AD derivatives and the point Jacobian against central finite
differences, float64 arrays of the documented shapes, and bad input as ValueError."""
import numpy as np
import pytest

import saltus

rng = np.random.default_rng(3)


@pytest.fixture
def iiwa(root):
    return saltus.Model.from_urdf(str(root / "models/benchmark/iiwa.urdf"), base="fixed")


def state(model):
    n = model.nv
    return rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)


def test_model_names_and_sizes(iiwa):
    assert iiwa.nq == iiwa.nv == 7
    assert len(iiwa.coordinate_names) == 7
    assert len(iiwa.body_names) >= 7
    assert iiwa.total_mass > 10
    np.testing.assert_allclose(iiwa.gravity, [0, 0, -9.81])


def test_rnea_is_mass_matrix_times_acceleration_plus_bias(iiwa):
    q, v, a = state(iiwa)
    tau = saltus.rnea(iiwa, q, v, a)
    M = saltus.crba(iiwa, q)
    assert tau.dtype == np.float64 and tau.shape == (7,)
    assert M.shape == (7, 7)
    np.testing.assert_allclose(M, M.T, atol=1e-12)
    np.testing.assert_allclose(tau, M @ a + saltus.nonlinear_effects(iiwa, q, v), atol=1e-10)
    np.testing.assert_allclose(saltus.aba(iiwa, q, v, tau), a, atol=1e-9)
    assert saltus.kinetic_energy(iiwa, q, v) == pytest.approx(0.5 * v @ M @ v, rel=1e-12)


def test_rnea_derivatives_against_finite_differences(iiwa):
    q, v, a = state(iiwa)
    dq, dv, da = saltus.rnea_derivatives(iiwa, q, v, a)
    h = 1e-6
    for k in range(7):
        e = np.zeros(7)
        e[k] = h
        fq = (saltus.rnea(iiwa, q + e, v, a) - saltus.rnea(iiwa, q - e, v, a)) / (2 * h)
        fv = (saltus.rnea(iiwa, q, v + e, a) - saltus.rnea(iiwa, q, v - e, a)) / (2 * h)
        np.testing.assert_allclose(dq[:, k], fq, atol=1e-6)
        np.testing.assert_allclose(dv[:, k], fv, atol=1e-6)
    np.testing.assert_allclose(da, saltus.crba(iiwa, q), atol=1e-12)
    _, _, dqdd_dtau = saltus.aba_derivatives(iiwa, q, v, saltus.rnea(iiwa, q, v, a))
    np.testing.assert_allclose(dqdd_dtau @ saltus.crba(iiwa, q), np.eye(7), atol=1e-9)


def test_point_jacobian_against_finite_differences_of_the_pose(iiwa):
    q, _, _ = state(iiwa)
    body = iiwa.body_names[-1]
    point = np.array([0.0, 0.0, 0.1])
    J = saltus.point_jacobian(iiwa, q, body, point)
    assert J.shape == (3, 7)
    index = iiwa.body_names.index(body)

    def position(x):
        T = saltus.forward_kinematics(iiwa, x)[index]
        return T[:3, :3] @ point + T[:3, 3]

    h = 1e-6
    for k in range(7):
        e = np.zeros(7)
        e[k] = h
        np.testing.assert_allclose(J[:, k], (position(q + e) - position(q - e)) / (2 * h), atol=1e-7)


def test_integer_and_strided_arrays_are_converted(iiwa):
    q = np.zeros(14)[::2]  # strided view
    tau = saltus.rnea(iiwa, q, np.zeros(7, dtype=np.int64), np.zeros(7))
    np.testing.assert_allclose(tau, saltus.nonlinear_effects(iiwa, np.zeros(7), np.zeros(7)))


def test_bundled_models_by_name(iiwa):
    assert saltus.Model.builtin("iiwa").body_names == iiwa.body_names
    assert saltus.Model.builtin("hyq", base="free").nq == 18
    hyq = saltus.Model.builtin("hyq", base="free_quaternion")
    assert (hyq.nq, hyq.nv) == (19, 18) and hyq.position_names[3] == "base_qw"
    assert saltus.Model.builtin("double_pendulum").nq == 2
    with pytest.raises(ValueError, match="not a bundled model"):
        saltus.Model.builtin("r2d2")


def test_bad_input_is_a_value_error_naming_it(iiwa, root):
    with pytest.raises(ValueError, match="rnea.*q"):
        saltus.rnea(iiwa, np.zeros(6), np.zeros(7), np.zeros(7))
    with pytest.raises(ValueError, match="no_such.urdf"):
        saltus.Model.from_urdf(str(root / "no_such.urdf"))
    with pytest.raises(ValueError, match="base"):
        saltus.Model.from_urdf(str(root / "models/benchmark/iiwa.urdf"), base="floating")
    with pytest.raises(ValueError, match="nothing"):
        saltus.point_jacobian(iiwa, np.zeros(7), "nothing")


def test_kernels_equal_the_commands(iiwa, root, saltus_binary):
    import json
    import subprocess

    q, v, tau = np.linspace(0.1, 0.7, 7), np.linspace(-1, 1, 7), np.arange(1.0, 8.0)
    fmt = lambda x: ",".join(repr(float(e)) for e in x)  # noqa: E731
    out = subprocess.run([saltus_binary, "inspect", str(root / "models/benchmark/iiwa.urdf"), "--json",
                          "--q=" + fmt(q), "--v=" + fmt(v), "--tau=" + fmt(tau)],
                         check=True, capture_output=True, text=True).stdout
    j = json.loads(out)
    np.testing.assert_allclose(saltus.crba(iiwa, q), np.array(j["M"]), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(saltus.nonlinear_effects(iiwa, q, v), np.array(j["h"]), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(saltus.aba(iiwa, q, v, tau), np.array(j["qdd"]), rtol=1e-10, atol=1e-10)
    assert j["coordinates"][0]["name"] if isinstance(j["coordinates"][0], dict) else j["coordinates"][0]
