"""The plug-in registry: the hook a plug-in package implements, the entry points read one
distribution at a time, and the registry that resolves plug-in names to classes.

The folder is named for what it holds, the registry, not "plugins": that name is taken by
the built-ins (the top-level plugins/ folder, the plateimpact_plugins package). It imports
base, model and solve (the contracts it checks plug-ins against)."""
