# Hand-written stub of the Rust extension imunoise._core (keep in sync with rust/bindings/).
import numpy as np
import numpy.typing as npt

__version__: str

def fit_wls(
    taus: npt.NDArray[np.float64],
    var: npt.NDArray[np.float64],
    edf: npt.NDArray[np.float64],
    terms: list[bool],
    reweight: int = 3,
    min_share: float = 0.25,
    min_z: float = 2.0,
) -> tuple[
    npt.NDArray[np.float64],  # (Q², N², B², K², R²)
    npt.NDArray[np.float64],  # (5, 5) covariance of the squares
    npt.NDArray[np.bool_],  # supported
    float,  # chi2
    int,  # dof
]: ...
