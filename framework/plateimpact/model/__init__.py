"""The model: sphere, plate and scenes (one or a batch), the contact
geometry, the plug-in contracts of the physics (resistance law, failure model, their shared
base), the impact model and its events, results and crater sections, the declarations of
their columns, and how they show in a notebook and as labelled tables (views, tables).
It imports only plateimpact.base."""
