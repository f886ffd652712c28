"""softdesign: patient-specific soft actuators from VMTK vessel exports."""

__version__ = "0.1.0"
