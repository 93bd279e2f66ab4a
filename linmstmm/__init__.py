"""linmstmm: natural frequencies, mode shapes and modal response of
multi-rigid-flexible-body systems by the linear transfer matrix method for
multibody systems (MSTMM, the "Rui method")."""

__version__ = "0.1.0"
