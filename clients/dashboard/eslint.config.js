// eslint (flat config): the recommended rules for the Node server and tests
// (lib/, test/, server.js) and the browser page (public/). CTest runs it as
// dashboard_lint_test; `npx eslint .` by hand.
import js from '@eslint/js';
import globals from 'globals';

export default [
  { ignores: ['node_modules/'] },
  js.configs.recommended,
  {
    files: ['**/*.js', '**/*.mjs'],
    languageOptions: { ecmaVersion: 2024, sourceType: 'module' },
    rules: {
      // Unused arguments name what a callback receives; unused variables are bugs.
      'no-unused-vars': ['error', { args: 'none', caughtErrors: 'none' }],
      eqeqeq: ['error', 'always'],
      'prefer-const': 'error',
      'no-var': 'error',
    },
  },
  { files: ['public/**/*.js'], languageOptions: { globals: globals.browser } },
  { files: ['lib/**/*.js', 'test/**/*.mjs', 'server.js', 'eslint.config.js'], languageOptions: { globals: globals.node } },
  // The browser test's page functions run in Chromium.
  { files: ['test/**/*.mjs'], languageOptions: { globals: { ...globals.node, ...globals.browser } } },
];
