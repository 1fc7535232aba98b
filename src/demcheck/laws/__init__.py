"""The contact laws, below the case: the seed models as records in their slots' registries, closed forms, a pair's
effective properties and the resolved model of a pair (docs/architecture.md, "The laws layer")."""
