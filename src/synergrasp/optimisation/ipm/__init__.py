"""The compiled interior-point kernel, by concern: how it is compiled and cached
(`compiled`), its data layout (`layout`), cone algebra (`cone_algebra`), linear systems
(`linear_systems`), stopping tests and certificates (`certificates`), the iteration
(`iteration`) and the compiled call per pose (`sets`). The front door is
`synergrasp.optimisation.ipm.solver`."""
