"""The contact's slots, below the case: one module per law (its record and its compiled force function)."""
