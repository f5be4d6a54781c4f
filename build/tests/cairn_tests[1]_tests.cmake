add_test([=[Projectile.MatchesExactDiscreteSemiImplicitEuler]=]  /work/main/build/tests/cairn_tests [==[--gtest_filter=Projectile.MatchesExactDiscreteSemiImplicitEuler]==] --gtest_also_run_disabled_tests)
set_tests_properties([=[Projectile.MatchesExactDiscreteSemiImplicitEuler]=]  PROPERTIES WORKING_DIRECTORY /work/main/build/tests SKIP_REGULAR_EXPRESSION [==[\[  SKIPPED \]]==] LABELS unit)
set(  cairn_tests_TESTS Projectile.MatchesExactDiscreteSemiImplicitEuler)
