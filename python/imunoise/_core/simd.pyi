# rust/bindings/simd.rs: the instruction-set level of the dispatched kernels.

def level() -> str:
    """The level the kernels use now: scalar, avx2, avx512 or ifma."""

def detected() -> str:
    """The best level this CPU has."""

def levels() -> list[str]:
    """Every level name, lowest first."""

def force(name: str | None) -> None:
    """Force the kernels down to `name` (None: the CPU's best again)."""
